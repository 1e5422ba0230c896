"""Inverse dynamics against OpenSim's own InverseDynamicsTool (Rajagopal2016 walking), a pendulum's closed form,
the power's product and the refusals."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pandas as pd
import pytest

from loper_analysis.dynamics.inverse_dynamics import (
    FootLoad,
    coordinate_speeds,
    generalized_forces,
    joint_powers_w,
    normalised_per_kg,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import read_mot
from loper_analysis.io.osim import quiet_opensim, read_marker_set, read_model, write_model
from tests.opensim_inverse_dynamics import opensim_inverse_dynamics
from tests.rajagopal_lab import DATA, GENERIC_OSIM, GRF_MOT, IK_SETUP, MARKER_SET, WALK_TRC, opensim_ik_reference

GRF_XML = DATA / "Rajagopal_grf_walk.xml"
#: The ExternalLoads file's own kinematics cut-off, used here for the coordinates of both engines.
CUTOFF_HZ = 6.0
#: Frames left out of the comparison at each end of the walk.
EDGE_FRAMES = 5
SAGITTAL = [f"{joint}_{side}" for joint in ("hip_flexion", "knee_angle", "ankle_angle") for side in "rl"]

G = 9.80665
PENDULUM_MASS_KG = 2.0
PENDULUM_COM_M = 0.4
PENDULUM_INERTIA_KGM2 = 0.05  # about the centre of mass, about the pin's axis
AMPLITUDE_RAD = 0.6
FREQUENCY_HZ = 1.0
FRAME_RATE_HZ = 100.0


# ---------------------------------------------------------------- OpenSim's own tool on the walk


@pytest.fixture(scope="module")
def walk(tmp_path_factory):
    """IK of the walk on Rajagopal2016 with the TRC's marker set, OpenSim's ID of it and this module's."""
    out = tmp_path_factory.mktemp("walk")
    model = read_model(GENERIC_OSIM)
    model.updateMarkerSet(read_marker_set(MARKER_SET))  # the model's own markers are not the TRC's
    model_osim = write_model(model, out / "walk.osim")
    coordinates = opensim_ik_reference(model_osim, IK_SETUP, WALK_TRC, out / "walk_ik.mot")
    reference = _opensim_inverse_dynamics(model_osim, out / "walk_ik.mot", out)
    grf = read_mot(GRF_MOT)  # inDegrees=no: read as written (N, m, N·m)
    loads = [
        FootLoad(
            body=f"calcn_{side}",
            time_s=grf["time_s"].to_numpy(),
            force_n=grf[[f"ground_force_{side}_v{a}" for a in "xyz"]].to_numpy(),
            point_m=grf[[f"ground_force_{side}_p{a}" for a in "xyz"]].to_numpy(),
            torque_nm=grf[[f"ground_torque_{side}_{a}" for a in "xyz"]].to_numpy(),
        )
        for side in "rl"
    ]
    model = read_model(model_osim)
    time_s = coordinates.pop("time_s").to_numpy()
    ours = generalized_forces(model, time_s, coordinates, loads, cutoff_hz=CUTOFF_HZ)
    return ours, reference


def _opensim_inverse_dynamics(model_osim, coordinates_mot, out) -> pd.DataFrame:
    """OpenSim's InverseDynamicsTool on ``coordinates_mot`` with the walk's ExternalLoads
    (:func:`tests.opensim_inverse_dynamics.opensim_inverse_dynamics`)."""
    osim = quiet_opensim()
    tree = ET.parse(GRF_XML)  # the setup's data file is relative to OpenSim's folders: point it at ours
    tree.getroot().find(".//datafile").text = str(GRF_MOT)
    tree.getroot().find(".//external_loads_model_kinematics_file").text = "Unassigned"
    tree.write(out / "grf_walk.xml")
    times = osim.TimeSeriesTable(str(coordinates_mot)).getIndependentColumn()
    return opensim_inverse_dynamics(model_osim, coordinates_mot, out / "grf_walk.xml", out, times, CUTOFF_HZ)


@pytest.mark.slow  # OpenSim's IK and ID tools on the whole Rajagopal2016 walk (6 s)
def test_the_walk_has_opensims_frames_and_columns(walk):
    ours, reference = walk
    assert len(ours) == len(reference) == 238  # the whole TRC, 0 .. 2.37 s
    np.testing.assert_allclose(ours["time_s"], reference["time_s"], rtol=0, atol=1e-9)
    # OpenSim's columns in the multibody tree's order, ours in the coordinate set's: the same coordinates
    assert sorted(_coordinate(c) for c in ours.columns[1:]) == sorted(_coordinate(c) for c in reference.columns[1:])
    assert "pelvis_ty_force_n" in ours.columns and "knee_angle_r_moment_nm" in ours.columns
    # OpenSim calls every coordinate that is not of motion type Rotational a force; the coupled knee_angle_*_beta
    # turn the patellae, so they are moments (N·m) here
    assert "knee_angle_r_beta_force" in reference.columns and "knee_angle_r_beta_moment_nm" in ours.columns


def _coordinate(column: str) -> str:
    """The coordinate of a generalised-force column, ours (``_moment_nm``, ``_force_n``) or OpenSim's."""
    for suffix in ("_moment_nm", "_force_n", "_moment", "_force"):
        if column.endswith(suffix):
            return column[: -len(suffix)]
    raise AssertionError(column)


@pytest.mark.slow
def test_every_generalised_force_matches_opensims_tool(walk):
    ours, reference = walk
    theirs = {_coordinate(c): reference[c].to_numpy() for c in reference.columns[1:]}
    for column in ours.columns[1:]:
        expected = theirs[_coordinate(column)][EDGE_FRAMES:-EDGE_FRAMES]
        tolerance = max(0.01 * np.max(np.abs(expected)), 1.0)  # as for the sagittal moments below
        np.testing.assert_allclose(ours[column].to_numpy()[EDGE_FRAMES:-EDGE_FRAMES], expected, atol=tolerance)


@pytest.mark.slow
@pytest.mark.parametrize("coordinate", SAGITTAL)
def test_sagittal_moments_match_opensims_inverse_dynamics_tool(walk, coordinate):
    ours, reference = walk
    mine = ours[f"{coordinate}_moment_nm"].to_numpy()[EDGE_FRAMES:-EDGE_FRAMES]
    theirs = reference[f"{coordinate}_moment"].to_numpy()[EDGE_FRAMES:-EDGE_FRAMES]
    peak = np.max(np.abs(theirs))
    assert peak > 20.0  # a real joint moment of walking, not a row of zeros
    # 1 % of the peak or 1 N·m: the same filter, splines, loads and solver as OpenSim's tool, so the two
    # differ by the rounding of the tool's .sto (8 decimals, ~5e-9 N·m measured); the bound leaves room for
    # another OpenSim build's spline fit while catching any wrong sign, axis, unit or filter.
    np.testing.assert_allclose(mine, theirs, rtol=0, atol=max(0.01 * peak, 1.0))


# ---------------------------------------------------------------- a pendulum's closed form


def _pendulum():
    """A body on a pin about ground's Z at the origin, its centre of mass PENDULUM_COM_M below the pin."""
    osim = quiet_opensim()
    model = osim.Model()
    model.setName("pendulum")
    model.setGravity(osim.Vec3(0, -G, 0))
    inertia = osim.Inertia(PENDULUM_INERTIA_KGM2, PENDULUM_INERTIA_KGM2, PENDULUM_INERTIA_KGM2)
    body = osim.Body("bob", PENDULUM_MASS_KG, osim.Vec3(0, -PENDULUM_COM_M, 0), inertia)
    model.addBody(body)
    pin = osim.PinJoint("pin", model.getGround(), osim.Vec3(0), osim.Vec3(0), body, osim.Vec3(0), osim.Vec3(0))
    pin.updCoordinate().setName("theta")
    model.addJoint(pin)
    model.finalizeConnections()
    model.initSystem()
    return model


def _swing(n_frames: int = 201) -> tuple[np.ndarray, np.ndarray]:
    """Time (s) and the prescribed angle theta = A sin(2 pi f t) (rad) at FRAME_RATE_HZ."""
    t = np.arange(n_frames) / FRAME_RATE_HZ
    return t, AMPLITUDE_RAD * np.sin(2 * np.pi * FREQUENCY_HZ * t)


@pytest.mark.parametrize("cutoff_hz", [None, CUTOFF_HZ])
def test_a_pendulums_moment_is_its_equation_of_motion(cutoff_hz):
    model = _pendulum()
    t, theta = _swing()
    forces = generalized_forces(model, t, pd.DataFrame({"theta": theta}), cutoff_hz=cutoff_hz)
    assert forces.columns.tolist() == ["time_s", "theta_moment_nm"]
    w = 2 * np.pi * FREQUENCY_HZ
    pin_inertia = PENDULUM_INERTIA_KGM2 + PENDULUM_MASS_KG * PENDULUM_COM_M**2
    # OpenSim's sign: the moment acts about +Z like theta; gravity pulls the bob back (m g l sin theta).
    expected = -pin_inertia * w**2 * theta + PENDULUM_MASS_KG * G * PENDULUM_COM_M * np.sin(theta)
    inner = slice(EDGE_FRAMES, -EDGE_FRAMES)
    error = np.abs(forces["theta_moment_nm"].to_numpy() - expected)[inner]
    peak = np.max(np.abs(expected))
    # 0.1 % of the peak: the quintic GCV spline's second derivative of a 1 Hz sine sampled at 100 Hz is off by
    # 0.03 % of the peak at most 5 frames in from the ends without a filter (8 % at the end frames themselves),
    # 0.002 % with the 6 Hz filter, whose padding continues the sine past the ends and whose gain at 1 Hz is
    # 1 - 2e-5 (measured, OpenSim 4.6).
    assert error.max() < 1e-3 * peak, (error.max(), peak)
    speeds = coordinate_speeds(model, t, pd.DataFrame({"theta": theta}), cutoff_hz=cutoff_hz)
    np.testing.assert_allclose(speeds["theta"][inner], (AMPLITUDE_RAD * w * np.cos(w * t))[inner], atol=1e-3)


def test_the_model_given_is_not_changed():
    model = _pendulum()
    t, theta = _swing()
    before = model.getForceSet().getSize()
    load = FootLoad("bob", t, np.tile([0.0, 10.0, 0.0], (t.size, 1)), np.zeros((t.size, 3)), np.zeros((t.size, 3)))
    generalized_forces(model, t, pd.DataFrame({"theta": theta}), [load], cutoff_hz=CUTOFF_HZ)
    assert model.getForceSet().getSize() == before


def test_a_load_on_the_pendulum_adds_its_moment():
    model = _pendulum()
    t, theta = _swing()
    coordinates = pd.DataFrame({"theta": theta})
    push = np.tile([5.0, 0.0, 0.0], (t.size, 1))  # 5 N along +X at the origin's 0.4 m below: about -Z
    point = np.tile([0.0, -PENDULUM_COM_M, 0.0], (t.size, 1))
    load = FootLoad("bob", t, push, point, np.zeros((t.size, 3)))
    free = generalized_forces(model, t, coordinates, cutoff_hz=CUTOFF_HZ)["theta_moment_nm"]
    loaded = generalized_forces(model, t, coordinates, [load], cutoff_hz=CUTOFF_HZ)["theta_moment_nm"]
    # r x F about Z = x F_y - y F_x = 0.4 * 5 = 2 N·m along +Z, which the joint need no longer supply.
    np.testing.assert_allclose(free - loaded, 2.0, atol=1e-9)


# ---------------------------------------------------------------- power and per-kg


def test_power_is_moment_times_speed():
    t = np.array([0.0, 0.01, 0.02])
    moments = pd.DataFrame({"time_s": t, "knee_angle_r_moment_nm": [10.0, -4.0, 2.5], "pelvis_tx_force_n": [1, 2, 3]})
    speeds = pd.DataFrame({"time_s": t, "knee_angle_r": [0.5, 2.0, -4.0], "pelvis_tx": [1.0, 1.0, -2.0]})
    powers = joint_powers_w(moments, speeds)
    assert powers.columns.tolist() == ["time_s", "knee_angle_r_power_w", "pelvis_tx_power_w"]
    assert powers["knee_angle_r_power_w"].tolist() == [5.0, -8.0, -10.0]
    assert powers["pelvis_tx_power_w"].tolist() == [1.0, 2.0, -6.0]
    per_kg = normalised_per_kg(powers, 80.0)
    assert per_kg.columns.tolist() == ["time_s", "knee_angle_r_power_w_per_kg", "pelvis_tx_power_w_per_kg"]
    assert per_kg["knee_angle_r_power_w_per_kg"].tolist() == [5.0 / 80, -8.0 / 80, -10.0 / 80]
    assert per_kg["time_s"].tolist() == t.tolist()


def test_power_refuses_a_moment_without_its_speed():
    t = np.array([0.0, 0.01])
    moments = pd.DataFrame({"time_s": t, "knee_angle_r_moment_nm": [1.0, 2.0]})
    with pytest.raises(LoperInputError, match="no column 'knee_angle_r'"):
        joint_powers_w(moments, pd.DataFrame({"time_s": t, "knee_angle_l": [1.0, 2.0]}))


@pytest.mark.parametrize("mass_kg", [0.0, -70.0, float("nan")])
def test_per_kg_refuses_a_mass_that_is_not_positive(mass_kg):
    with pytest.raises(LoperInputError, match="mass_kg must be a positive number"):
        normalised_per_kg(pd.DataFrame({"time_s": [0.0], "x_moment_nm": [1.0]}), mass_kg)


# ---------------------------------------------------------------- refusals


def test_a_coordinate_the_model_lacks_is_named():
    model = _pendulum()
    t, theta = _swing()
    with pytest.raises(LoperInputError, match=r"column 'hip_flexion_r' is not a coordinate of model pendulum"):
        generalized_forces(model, t, pd.DataFrame({"theta": theta, "hip_flexion_r": theta}), cutoff_hz=CUTOFF_HZ)


def test_non_finite_coordinates_are_named_with_their_frame():
    model = _pendulum()
    t, theta = _swing()
    theta[17] = np.nan
    with pytest.raises(LoperInputError, match=r"'theta' is not finite at frame 17 \(0.17 s\): nan"):
        generalized_forces(model, t, pd.DataFrame({"theta": theta}), cutoff_hz=CUTOFF_HZ)


def test_time_that_does_not_increase_is_named():
    model = _pendulum()
    t, theta = _swing()
    t[30] = t[29]
    with pytest.raises(LoperInputError, match=r"time_s must increase strictly; frame 30 \(0.29 s\)"):
        generalized_forces(model, t, pd.DataFrame({"theta": theta}), cutoff_hz=CUTOFF_HZ)


def test_a_load_on_a_body_the_model_lacks_is_named():
    model = _pendulum()
    t, theta = _swing()
    zeros = np.zeros((t.size, 3))
    with pytest.raises(LoperInputError, match=r"loads\[0\]: body 'calcn_r' is not a body of model pendulum"):
        generalized_forces(
            model, t, pd.DataFrame({"theta": theta}), [FootLoad("calcn_r", t, zeros, zeros, zeros)], cutoff_hz=CUTOFF_HZ
        )


def test_loads_that_do_not_cover_the_frames_are_refused():
    model = _pendulum()
    t, theta = _swing()
    zeros = np.zeros((t.size - 10, 3))
    short = FootLoad("bob", t[:-10], zeros, zeros, zeros)
    with pytest.raises(
        LoperInputError, match=r"loads\[0\]: time_s 0 .. 1.9 s does not cover the coordinates' 0 .. 2 s"
    ):
        generalized_forces(model, t, pd.DataFrame({"theta": theta}), [short], cutoff_hz=CUTOFF_HZ)


def test_a_cutoff_above_half_the_frame_rate_is_refused():
    model = _pendulum()
    t, theta = _swing()
    with pytest.raises(LoperInputError, match=r"cutoff_hz must be below half the frame rate \(50 Hz\), got 60"):
        generalized_forces(model, t, pd.DataFrame({"theta": theta}), cutoff_hz=60)
