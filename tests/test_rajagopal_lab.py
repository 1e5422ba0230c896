"""The Rajagopal2016 subject as a lab's C3D files (``tests/rajagopal_lab.py``), and OpenSim's own scaling
and IK of it: the files give the TRC's markers and the GRF .mot's loads back through our readers; the
committed example files are the generator's output.

Known answers are the source files themselves, read here independently of the generator (the .mot with
pandas, the lab frame mapped by hand), and facts measured on them (stance times, body weight).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.gait.contacts import PlateForce, foot_contacts
from loper_analysis.gait.grf import plate_loads
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.io.opensim_tables import read_markers, write_trc
from loper_analysis.io.osim import quiet_opensim
from loper_analysis.motion.markers import rotate_markers
from tests.rajagopal_lab import (
    GENERIC_OSIM,
    GRF_MOT,
    IK_SETUP,
    MARKER_SET,
    SCALE_SETUP,
    STATIC_GAPS,
    STATIC_TRC,
    SUBJECT_MASS_KG,
    WALK_TRC,
    ik_marker_errors_path,
    model_to_lab,
    opensim_ik_reference,
    opensim_scale_reference,
    static_markers,
    write_lab_files,
)

EXAMPLE_RAW = Path(__file__).resolve().parents[1] / "examples" / "rajagopal2016" / "raw" / "R11"
G = 9.80665
#: Stances of the GRF .mot in the order of the plates: foot, first and last sample with force (s, 2000 Hz).
STANCES = [("right", 0.2480, 1.0465), ("left", 0.8170, 1.6125), ("right", 1.3925, 2.1910)]
#: float32 coordinates in mm: a relative rounding error of at most 2**-24 (measured 5.9e-8, 0.12 µm).
FLOAT32_RTOL = 2.0**-24


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    return write_lab_files(tmp_path_factory.mktemp("lab"))


@pytest.fixture(scope="module")
def grf() -> pd.DataFrame:
    """The GRF .mot as a table (header of 6 lines), read without the package."""
    return pd.read_csv(GRF_MOT, sep="\t", skiprows=6)


def test_the_lab_frame_is_the_model_frame_turned_back_by_minus_90_about_x():
    p = np.array([[0.3, 1.2, -0.25], [np.nan, np.nan, np.nan]])
    lab = model_to_lab(p)
    np.testing.assert_array_equal(lab[0], [0.3, 0.25, 1.2])  # (x, y, z) -> (x, -z, y)
    np.testing.assert_allclose(rotate_markers(lab, (-90, 0, 0)), p, rtol=0, atol=1e-15)  # missing stays missing


@pytest.mark.parametrize("trial, trc, n_frames", [("walk-nodevice", WALK_TRC, 238), ("static", STATIC_TRC, 153)])
def test_markers_read_back_as_the_trc(lab, trial, trc, n_frames):
    rec = read_c3d(lab[trial])
    time_s, X, names = static_markers(trc, STATIC_GAPS if trial == "static" else {})
    assert rec.marker_labels == ["Subject11:" + n for n in names] and len(names) == 41
    assert rec.point_rate_hz == 100.0 and rec.first_frame == 0 and rec.markers_m.shape == (n_frames, 41, 3)
    assert rec.time_s[0] == time_s[0] == 0.0
    np.testing.assert_allclose(rec.time_s, time_s, rtol=0, atol=1e-12)
    Y = rotate_markers(rec.markers_m, (-90, 0, 0))
    np.testing.assert_array_equal(np.isnan(Y), np.isnan(X))  # missing only where the lab's static trial lacks them
    assert np.isnan(X).any(axis=2).sum() == (26 if trial == "static" else 0)
    np.testing.assert_allclose(Y, X, rtol=FLOAT32_RTOL, atol=1e-12)
    assert np.nanmax(np.abs(Y - X)) < 2.5e-7  # m


def test_the_walkway_plates_give_the_mot_back(lab, grf):
    rec = read_c3d(lab["walk-nodevice"])
    assert rec.analog_rate_hz == 2000.0 and rec.analogs.shape == (238 * 20, 18)
    assert rec.analog_labels[:6] == ["Fx1", "Fy1", "Fz1", "Mx1", "My1", "Mz1"]
    assert rec.analog_units[:6] == ["N", "N", "N", "Nmm", "Nmm", "Nmm"]
    plates = read_force_platforms(lab["walk-nodevice"])
    assert [p.type for p in plates] == [2, 2, 2]
    rows = grf.iloc[: 238 * 20]  # the .mot's rows at the analog samples (k / 2000 s from 0)
    np.testing.assert_allclose(plates[0].time_s, rows["time"], rtol=0, atol=1e-12)
    for plate, (side, t_on, t_off) in zip(plates, STANCES):
        s = side[0]
        on = (rows["time"] >= t_on - 1e-9) & (rows["time"] <= t_off + 1e-9)
        vy = rows[f"ground_force_{s}_vy"].to_numpy()
        first, last = np.flatnonzero(on)[[0, -1]]
        assert (vy[first : last + 1] > 0).all() and vy[first - 1] == 0 and vy[last + 1] == 0  # the stance's rows
        loads = plate_loads(plate.number, plate.time_s, plate.force_n, plate.moment_nm, plate.corners_m)
        np.testing.assert_allclose(loads.rest_force_n, [0.0, 0.0, -6.0], atol=1e-5)  # not zeroed: -6 N at rest
        expected_force = np.column_stack(
            [rows[f"ground_force_{s}_vx"], -rows[f"ground_force_{s}_vz"], rows[f"ground_force_{s}_vy"]]
        )
        expected_force[~on.to_numpy()] = 0.0  # another plate holds the foot's other stance
        np.testing.assert_allclose(loads.force_n[:, 2], expected_force[:, 2], rtol=0, atol=1e-3)
        np.testing.assert_allclose(loads.force_n, expected_force, rtol=0, atol=1e-3)
        assert np.all(loads.force_n[~on.to_numpy()] == 0.0)
        loaded = loads.loaded
        assert loaded.sum() > 0.9 * on.sum() and not loaded[~on.to_numpy()].any()
        cop = np.column_stack(
            [rows[f"ground_force_{s}_px"], -rows[f"ground_force_{s}_pz"], rows[f"ground_force_{s}_py"]]
        )  # m, floor at z = 0
        np.testing.assert_allclose(loads.cop_m[loaded], cop[loaded], rtol=0, atol=1e-4)  # 0.1 mm
        np.testing.assert_allclose(
            loads.free_moment_nm[loaded], rows[f"ground_torque_{s}_y"][loaded], rtol=0, atol=1e-4
        )
        corners = plate.corners_m
        assert np.all(corners[:, 2] == 0.0)
        inside = cop[on.to_numpy()]
        assert np.all((inside[:, :2] > corners[:, :2].min(axis=0)) & (inside[:, :2] < corners[:, :2].max(axis=0)))
    boxes = [(p.corners_m[:, :2].min(axis=0), p.corners_m[:, :2].max(axis=0)) for p in plates]
    for i in range(3):
        for j in range(i + 1, 3):
            apart = np.any(boxes[i][1] <= boxes[j][0]) or np.any(boxes[j][1] <= boxes[i][0])
            assert apart, (i + 1, j + 1)


def test_the_pipeline_puts_each_stance_on_its_foot(lab):
    rec = read_c3d(lab["walk-nodevice"])
    plates = read_force_platforms(lab["walk-nodevice"])
    forces = [PlateForce(p.number, p.time_s, p.force_n[:, 2] + 6.0, p.corners_m) for p in plates]
    heels = {
        "right": rec.markers_m[:, rec.marker_labels.index("Subject11:R.Heel")],
        "left": rec.markers_m[:, rec.marker_labels.index("Subject11:L.Heel")],
    }
    contacts = foot_contacts(forces, rec.time_s, heels, vertical_axis=2)
    assert contacts["side"].tolist() == [side for side, _, _ in STANCES]
    assert (contacts["flag"] == "ok").all()
    # heel strike at 50 N up, toe off at 20 N down (measured on the .mot)
    np.testing.assert_allclose(contacts["start_s"], [0.2817, 0.8506, 1.4263], atol=5e-4)
    np.testing.assert_allclose(contacts["end_s"], [1.0234, 1.5892, 2.1674], atol=5e-4)
    # the left foot also stands on the floor with no force (before 0.4 s, after 2.0 s): no heel on the floor is
    # over a plate but that of the plate's foot during its stance; the other heel stays 5 cm away or more
    for plate, (side, t_on, t_off) in zip(plates, STANCES):
        low, high = plate.corners_m[:, :2].min(axis=0), plate.corners_m[:, :2].max(axis=0)
        for heel_side, heel in heels.items():
            down = heel[:, 2] < 0.06  # m above the floor
            xy = heel[down, :2]
            outside = np.hypot(*np.maximum(np.maximum(low - xy, xy - high), 0.0).T)
            if heel_side == side:
                on_times = rec.time_s[down][outside == 0.0]
                assert t_on - 0.1 < on_times.min() and on_times.max() < t_off + 0.1
            else:
                assert outside.min() > 0.05, (plate.number, heel_side)


def test_the_static_plates_carry_the_weight(lab, tmp_path):
    rec = read_c3d(lab["static"])
    assert rec.analog_rate_hz == 1000.0 and rec.analogs.shape == (153 * 10, 12)
    plates = read_force_platforms(lab["static"])
    total = sum(p.force_n for p in plates)
    np.testing.assert_allclose(total, np.tile([0.0, 0.0, SUBJECT_MASS_KG * G], (1530, 1)), rtol=0, atol=1e-3)
    np.testing.assert_allclose(
        [plates[0].force_n[0, 2], plates[1].force_n[0, 2]],
        [0.52 * SUBJECT_MASS_KG * G, 0.48 * SUBJECT_MASS_KG * G],
        atol=1e-3,
    )
    for plate, side in zip(plates, "RL"):  # each plate lies under its foot
        _, X, names = read_markers(STATIC_TRC)
        heel = X[0, names.index(f"{side}.Heel")]
        lab_heel = np.array([heel[0], -heel[2]])
        low, high = plate.corners_m[:, :2].min(axis=0), plate.corners_m[:, :2].max(axis=0)
        assert np.all((lab_heel > low) & (lab_heel < high))
    other = write_lab_files(tmp_path, subject_prefix="", mass_kg=85.0)
    plates = read_force_platforms(other["static"])
    np.testing.assert_allclose(sum(p.force_n[:, 2] for p in plates), 85.0 * G, rtol=0, atol=1e-3)
    assert read_c3d(other["static"]).marker_labels[:2] == ["R.Shoulder", "L.Shoulder"]


def test_missing_markers_stay_missing(tmp_path):
    time_s, X, names = read_markers(STATIC_TRC)
    X[:10, names.index("R.Knee")] = np.nan  # a gap at the start, one frame, a marker missing throughout
    X[50, names.index("L.Toe")] = np.nan
    X[:, names.index("S2")] = np.nan
    gappy = write_trc(tmp_path / "gappy.trc", time_s, X, names)
    rec = read_c3d(write_lab_files(tmp_path / "lab", static_trc=gappy, static_gaps={})["static"])
    Y = rotate_markers(rec.markers_m, (-90, 0, 0))
    np.testing.assert_array_equal(np.isnan(Y), np.isnan(X))
    assert np.isnan(X).any(axis=2).sum() == 11 + 153
    np.testing.assert_allclose(Y, X, rtol=FLOAT32_RTOL, atol=1e-12)


def test_the_files_are_deterministic(lab, tmp_path):
    again = write_lab_files(tmp_path)
    for trial, path in lab.items():
        assert path.read_bytes() == again[trial].read_bytes(), trial


def test_the_example_raw_files_are_the_generators(lab):
    for trial, path in lab.items():
        assert (EXAMPLE_RAW / f"{trial}.c3d").read_bytes() == path.read_bytes(), trial


@pytest.fixture(scope="module")
def scaled(tmp_path_factory):
    return opensim_scale_reference(
        GENERIC_OSIM,
        SCALE_SETUP,
        STATIC_TRC,
        70.0,
        tmp_path_factory.mktemp("scale") / "scaled.osim",
        marker_set_xml=MARKER_SET,
    )


def test_opensim_scales_the_generic_model_with_the_pipelines_marker_set(scaled, tmp_path):
    osim = quiet_opensim()
    model = osim.Model(str(scaled))
    state = model.initSystem()
    assert model.getTotalMass(state) == pytest.approx(70.0, abs=1e-9)
    _, _, names = read_markers(STATIC_TRC)
    markers = model.getMarkerSet()
    assert sorted(markers.get(i).getName() for i in range(markers.getSize())) == sorted(names)  # the others deleted
    assert model.getNumCoordinates() == 39
    with pytest.raises(RuntimeError, match="no markers"):  # the model's own markers are named RASI, ...
        opensim_scale_reference(GENERIC_OSIM, SCALE_SETUP, STATIC_TRC, 70.0, tmp_path / "x.osim")


def test_opensim_ik_of_the_walking_trial(scaled, tmp_path):
    out = tmp_path / "walk_ik.mot"
    angles = opensim_ik_reference(scaled, IK_SETUP, WALK_TRC, out)
    osim = quiet_opensim()
    model = osim.Model(str(scaled))  # kept alive while its coordinate set is used
    coordinates = model.getCoordinateSet()
    names = [coordinates.get(i).getName() for i in range(coordinates.getSize())]
    assert angles.columns.tolist() == ["time_s", *names] and len(names) == 39
    time_s, _, _ = read_markers(WALK_TRC)
    np.testing.assert_allclose(angles["time_s"], time_s, rtol=0, atol=1e-9)  # the setup's 0 .. 2.37 s: all 238 frames
    lines = out.read_text().splitlines()
    assert "inDegrees=yes" in lines[: lines.index("endheader")]
    raw = pd.read_csv(out, sep="\t", skiprows=lines.index("endheader") + 1)
    raw.columns = [c.strip() for c in raw.columns]
    np.testing.assert_allclose(np.degrees(angles["knee_angle_r"]), raw["knee_angle_r"], rtol=1e-12)  # file: degrees
    np.testing.assert_allclose(angles["pelvis_tx"], raw["pelvis_tx"], rtol=1e-12)  # m, not converted
    # the knee's coupled coordinates are written in rad and follow the knee angle (coupler constraint)
    np.testing.assert_allclose(angles["knee_angle_r_beta"], raw["knee_angle_r_beta"], rtol=1e-12)
    np.testing.assert_allclose(angles["knee_angle_l_beta"], angles["knee_angle_l"], rtol=0, atol=1e-7)
    assert 1.0 < angles["knee_angle_r"].max() < 1.2  # rad: a peak swing-phase knee flexion of about 65 deg
    assert angles["pelvis_tx"].iloc[-1] - angles["pelvis_tx"].iloc[0] == pytest.approx(2.97, abs=0.01)  # along +x
    assert (angles["subtalar_angle_r"] == 0).all() and (angles["mtp_angle_l"] == 0).all()  # locked in the model
    errors = pd.read_csv(ik_marker_errors_path(out), sep="\t", skiprows=6)
    assert len(errors) == 238
    # the model is not scaled (the setup's model scaler has no scaling order): errors of centimetres
    assert 0.02 < errors["marker_error_RMS"].mean() < 0.05  # measured 0.0348 m
    assert errors["marker_error_max"].max() < 0.10  # measured 0.087 m
