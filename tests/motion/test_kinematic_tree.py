"""The kinematic tree (loper_analysis.motion.kinematic_tree) against OpenSim's own marker kinematics.

Peer engine: OpenSim places every marker for the same coordinates (``marker_positions``); the tree must place
them within rounding, on the generated model (planar and pin joints), gait2392 (custom joints with spline
knee translations) and Rajagopal2016 (universal joints, locked coordinates, coupler constraints). The
Jacobian is checked against central differences of the tree's own positions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.io.osim import quiet_opensim, read_model
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.kinematic_tree import (
    CHECK_TOLERANCE_M,
    UnsupportedModel,
    check_against_opensim,
    kinematic_tree,
)
from loper_analysis.motion.model import build_lower_body_model
from tests.gait2392_models import gait2392_with_markers

ROOT = Path(__file__).resolve().parents[2]
RAJAGOPAL = ROOT / "tests" / "data" / "rajagopal2016" / "Rajagopal2016.osim"


@pytest.fixture(scope="module")
def models():
    rajagopal = read_model(RAJAGOPAL)
    rajagopal.initSystem()
    return {
        "generated": build_lower_body_model(1.8, 75.0),
        "gait2392": gait2392_with_markers(),
        "rajagopal2016": rajagopal,
    }


@pytest.mark.parametrize("name", ["generated", "gait2392", "rajagopal2016"])
def test_the_tree_places_every_marker_where_opensim_does(models, name):
    model = models[name]
    tree = kinematic_tree(model)
    assert check_against_opensim(model, tree, n_poses=12, seed=3) < 1e-12  # metres: rounding only
    assert len(tree.marker_names) == model.getMarkerSet().getSize()


def test_the_knee_splines_hold_beyond_their_knots(models):
    """gait2392's knee translations are SimmSplines of the knee angle over -120..10 deg; OpenSim extrapolates
    them linearly, and so must the tree."""
    model = models["gait2392"]
    tree = kinematic_tree(model)
    knee = np.radians([-150.0, -119.9, -60.3, -1.0, 9.99, 30.0])
    i = tree.coordinate_names.index("knee_angle_r")
    expected = marker_positions(model, {"knee_angle_r": knee}, list(tree.marker_names))
    for k, angle in enumerate(knee):
        q = tree.default_q.copy()
        q[i] = angle
        np.testing.assert_allclose(tree.markers(q)[0], expected[k], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["generated", "gait2392", "rajagopal2016"])
def test_the_jacobian_is_the_derivative_of_the_positions(models, name, rng):
    tree = kinematic_tree(models[name])
    lo, hi = tree.range_q[:, 0], tree.range_q[:, 1]
    q = lo + (hi - lo) * rng.uniform(0.2, 0.8, lo.size)
    _, J = tree.markers(q)
    h = 1e-6
    for c in range(q.size):
        step = np.zeros(q.size)
        step[c] = h
        numeric = (tree.markers(q + step)[0] - tree.markers(q - step)[0]) / (2 * h)
        if tree.dependent[c]:  # a coupled coordinate follows its independent one: its column is folded there
            np.testing.assert_array_equal(J[:, :, c], 0.0)
        else:
            np.testing.assert_allclose(J[:, :, c], numeric, rtol=0, atol=1e-7, err_msg=tree.coordinate_names[c])


def test_rajagopals_patella_follows_the_knee_through_its_coupler(models):
    tree = kinematic_tree(models["rajagopal2016"])
    names = tree.coordinate_names
    pairs = {names[d]: names[i] for d, i in tree.coupled}
    assert pairs == {"knee_angle_r_beta": "knee_angle_r", "knee_angle_l_beta": "knee_angle_l"}
    assert tree.locked.sum() == 8  # subtalar, mtp and wrist angles are locked in the distributed model
    coupler = quiet_opensim().CoordinateCouplerConstraint.safeDownCast(
        models["rajagopal2016"].getConstraintSet().get("patellofemoral_knee_angle_r_con")
    )
    q = tree.default_q.copy()
    q[names.index("knee_angle_r")] = 0.7
    P, _ = tree.markers(q)  # the tree sets the coupled coordinate itself
    expected_beta = coupler.getFunction().calcValue(quiet_opensim().Vector(1, 0.7))
    q[names.index("knee_angle_r_beta")] = expected_beta
    opensim = marker_positions(models["rajagopal2016"], dict(zip(names, q[:, None])), list(tree.marker_names))
    np.testing.assert_allclose(P, opensim[0], rtol=0, atol=1e-12)


def test_a_ball_joint_is_refused_by_name():
    osim = quiet_opensim()
    model = osim.Model()
    body = osim.Body("ball", 1.0, osim.Vec3(0), osim.Inertia(0.1))
    model.addBody(body)
    model.addJoint(osim.BallJoint("shoulder", model.getGround(), body))
    model.addMarker(osim.Marker("M", body, osim.Vec3(0.1, 0, 0)))
    model.initSystem()
    with pytest.raises(UnsupportedModel, match="joint 'shoulder' is a BallJoint"):
        kinematic_tree(model)


def test_the_check_catches_a_tree_of_another_model(models):
    """gait2392's tree against gait2392 with longer thighs: the markers below the hips move, and the check
    names the distance."""
    from tests.gait2392_models import scaled_gait2392

    longer = scaled_gait2392({"femur": 1.1}, 75.0, markers=True)
    longer.initSystem()
    with pytest.raises(UnsupportedModel, match=r"places markers up to 0\.0[1-9]"):
        check_against_opensim(longer, kinematic_tree(models["gait2392"]))
    assert CHECK_TOLERANCE_M == 1e-9


def test_marker_positions_from_the_tree_are_opensims_with_clamped_locked_and_coupled_coordinates():
    """``marker_positions`` places long trajectories with the tree: it must set coordinates as OpenSim's
    ``Coordinate.setValue`` does. A clamped knee given angles beyond its range is placed there (``setValue``
    does not clamp), a locked coordinate given values stays at its default, and Rajagopal's coupled patella is
    placed where it is given (couplers not enforced); OpenSim placing the same frames is the answer."""
    from loper_analysis.motion.ik import TREE_MIN_FRAMES
    from loper_analysis.motion.opensim_ik import opensim_marker_positions

    rajagopal = read_model(RAJAGOPAL)
    cs = rajagopal.getCoordinateSet()
    cs.get("knee_angle_r").setDefaultClamped(True)
    rajagopal.initSystem()
    tree = kinematic_tree(rajagopal)
    assert tree.locked[tree.coordinate_names.index("subtalar_angle_r")]
    n = TREE_MIN_FRAMES
    lo, hi = tree.range_q[tree.coordinate_names.index("knee_angle_r")]
    values = {
        "knee_angle_r": np.linspace(lo - 0.3, hi + 0.3, n),  # beyond both bounds
        "subtalar_angle_r": np.full(n, 0.3),  # locked: OpenSim leaves it at its default
        "knee_angle_l_beta": np.linspace(-0.5, 0.5, n),  # coupled: placed as given
        "hip_flexion_l": np.linspace(-0.4, 0.8, n),
    }
    names = list(tree.marker_names)
    positions = marker_positions(rajagopal, values, names[::-1])
    expected = opensim_marker_positions(rajagopal, values, names[::-1])
    assert np.abs(expected[0] - expected[-1]).max() > 0.1  # the trajectories move the markers
    np.testing.assert_allclose(positions, expected, rtol=0, atol=1e-12)
