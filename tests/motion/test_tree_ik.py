"""IK on the kinematic tree (loper_analysis.motion.tree_ik) against OpenSim's InverseKinematicsSolver.

Peer engine: OpenSim's solver on the same model, markers, weights and tasks, at the pipeline's accuracy
(``ik.opensim_accuracy``, 1e-6). The tree must reach the same angles (within 0.05 deg RMS for hip, knee and
ankle flexion and pelvis tilt) and an objective no worse than OpenSim's, on simulated gait2392 walking and on
OpenSim's gait2392 tutorial static trial (a file recorded by others).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.io.opensim_tables import read_markers
from loper_analysis.motion.ik import inverse_kinematics, marker_positions
from loper_analysis.motion.kinematic_tree import kinematic_tree
from loper_analysis.motion.model import build_lower_body_model
from loper_analysis.motion.tree_ik import tree_inverse_kinematics
from loper_analysis.synthetic.gait2392_coordinates import gait2392_coordinates
from loper_analysis.synthetic.gait_curves import NominalGait
from loper_analysis.synthetic.walking import leg_length_from_height, walking_kinematics
from tests.gait2392_models import gait2392_with_markers

ROOT = Path(__file__).resolve().parents[2]
STATIC_TRC = ROOT / "tests" / "data" / "gait2392" / "subject01_static.trc"
#: gait2392's flexion angles and pelvis tilt, the angles the study reads.
STUDY_ANGLES = ("hip_flexion_r", "knee_angle_r", "ankle_angle_r", "hip_flexion_l", "knee_angle_l", "ankle_angle_l")
#: Largest RMS difference (deg) from OpenSim's solver allowed for the study's angles.
AGREEMENT_DEG = 0.05
#: The tree solver's step tolerance (its default, ``ik.tree_step_tolerance``): it stops when a step moves no
#: coordinate by more than this (rad or m).
STEP_TOLERANCE = 1e-6


@pytest.fixture(scope="module")
def gait2392():
    return gait2392_with_markers()


@pytest.fixture(scope="module")
def walking(gait2392):
    """1.5 s of simulated walking at 128 Hz on gait2392's 39 markers, with 2 mm noise and a gap."""
    rng = np.random.default_rng(11)
    coordinates, _ = walking_kinematics(
        1.5, 128.0, NominalGait(), rng, timing_cv=0.03, amplitude_cv=0.05, leg_length_m=leg_length_from_height(1.8)
    )
    truth = gait2392_coordinates(coordinates, 0.05)
    markers = gait2392.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    values = {c: truth[c].to_numpy(float) for c in truth.columns if c != "time_s"}
    X = marker_positions(gait2392, values, labels) + rng.normal(0.0, 2e-3, (len(truth), len(labels), 3))
    X[40:70, labels.index("R.Shank.Front")] = np.nan
    return truth["time_s"].to_numpy(float), X, labels


def _rms_deg(a, b, names):
    return {c: float(np.degrees(np.sqrt(np.nanmean((a[c] - b[c]) ** 2)))) for c in names}


def _objective(tree, q, X, labels, weights):
    """OpenSim's marker objective: the weighted mean squared marker distance (m^2) of one frame."""
    P, _ = tree.markers(np.nan_to_num(q))
    P = P[[tree.marker_names.index(m) for m in labels]]
    present = np.isfinite(X).all(axis=1)
    w = weights[present]
    return float((w * ((P - X)[present] ** 2).sum(axis=1)).sum() / w.sum())


def test_walking_gait2392_agrees_with_opensim(gait2392, walking):
    t, X, labels = walking
    weights = {m: (2.0 if "ASIS" in m else 1.0) for m in labels}
    ours = inverse_kinematics(gait2392, t, X, labels, marker_weights=weights, solver="tree")
    theirs = inverse_kinematics(gait2392, t, X, labels, marker_weights=weights, solver="opensim")
    assert ours.solver == "tree" and theirs.solver == "opensim"
    rms = _rms_deg(ours.frame(), theirs.frame(), (*STUDY_ANGLES, "pelvis_tilt"))
    assert max(rms.values()) < AGREEMENT_DEG / 5, rms  # measured 0.002-0.006 deg
    tree = kinematic_tree(gait2392)
    w = np.array([weights[m] for m in labels])
    for k in range(0, len(t), 16):  # the tree's optimum is no worse than OpenSim's (which stops at 1e-6)
        assert _objective(tree, ours.coordinates[k], X[k], labels, w) <= _objective(
            tree, theirs.coordinates[k], X[k], labels, w
        ) * (1 + 1e-9)


def test_coordinate_tasks_weigh_as_in_opensim(gait2392, walking):
    """A task's weight counts against the markers' weighted mean (OpenSim's normalisation): a wrong scale
    would move the task's coordinate and its neighbours by degrees."""
    t, X, labels = walking
    tasks = {"lumbar_extension": (5e-4, 0.2), "hip_rotation_r": (1e-3, None)}
    ours = inverse_kinematics(gait2392, t[:48], X[:48], labels, coordinate_tasks=tasks, solver="tree")
    theirs = inverse_kinematics(gait2392, t[:48], X[:48], labels, coordinate_tasks=tasks, solver="opensim")
    rms = _rms_deg(ours.frame(), theirs.frame(), ("lumbar_extension", "hip_rotation_r", *STUDY_ANGLES))
    assert max(rms.values()) < AGREEMENT_DEG / 5, rms
    untasked = inverse_kinematics(gait2392, t[:48], X[:48], labels, solver="tree").frame()
    shift = _rms_deg(ours.frame(), untasked, ("lumbar_extension",))["lumbar_extension"]
    assert shift > 0.5  # the task pulls the lumbar extension by degrees: the weights matter


def test_opensims_tutorial_static_trial_agrees_with_opensim(gait2392):
    t, X, labels = read_markers(STATIC_TRC)
    markers = gait2392.getMarkerSet()
    weights = {markers.get(i).getName(): 1.0 for i in range(markers.getSize())}
    weights = {m: (w if m in labels else 0.0) for m, w in weights.items()}
    sel = slice(0, 300, 5)
    ours = inverse_kinematics(gait2392, t[sel], X[sel], labels, marker_weights=weights, solver="tree")
    theirs = inverse_kinematics(gait2392, t[sel], X[sel], labels, marker_weights=weights, solver="opensim")
    rms = _rms_deg(ours.frame(), theirs.frame(), (*STUDY_ANGLES, "pelvis_tilt"))
    assert max(rms.values()) < AGREEMENT_DEG / 5, rms  # measured 0.0008-0.0018 deg over all 300 frames
    assert np.nanmean(ours.marker_rms_m) <= np.nanmean(theirs.marker_rms_m) + 1e-9  # 37.9 mm: unscaled model


def test_locked_and_clamped_coordinates_hold(walking):
    """A locked coordinate stays at its default; a clamped one within its range, however the markers pull."""
    model = gait2392_with_markers()
    cs = model.getCoordinateSet()
    cs.get("lumbar_rotation").setDefaultLocked(True)
    cs.get("lumbar_rotation").setDefaultValue(0.1)
    cs.get("knee_angle_r").setDefaultClamped(True)
    cs.get("knee_angle_r").setRangeMin(-0.4)
    model.initSystem()
    t, X, labels = walking
    ours = inverse_kinematics(model, t, X, labels, solver="tree").frame()
    theirs = inverse_kinematics(model, t, X, labels, solver="opensim").frame()
    np.testing.assert_array_equal(ours["lumbar_rotation"], 0.1)
    assert ours["knee_angle_r"].min() == pytest.approx(-0.4, abs=1e-12)
    # OpenSim holds the same bound (its optimiser stops just inside it: measured -0.39995)
    assert -0.4 <= theirs["knee_angle_r"].min() < -0.399
    free = theirs["knee_angle_r"] > -0.4 + 1e-3
    rms = np.degrees(np.sqrt(np.mean((ours["hip_flexion_l"] - theirs["hip_flexion_l"])[free] ** 2)))
    assert rms < AGREEMENT_DEG


def test_frames_left_out_are_nan_and_errors_are_distances(rng):
    model = build_lower_body_model(1.8, 75.0)
    tree = kinematic_tree(model)
    q = np.tile(tree.default_q, (5, 1))
    q[:, tree.coordinate_names.index("knee_flexion_l")] = np.linspace(0.1, 0.5, 5)
    X = np.array([tree.markers(row)[0] for row in q])
    X[3, 2] += [0.0, 0.0, 0.004]  # one marker 4 mm out of the sagittal plane in frame 3
    solution = tree_inverse_kinematics(
        tree, X, list(tree.marker_names), np.ones(len(tree.marker_names)), frames=np.array([0, 2, 3])
    )
    assert np.isnan(solution.coordinates[[1, 4]]).all() and np.isnan(solution.marker_errors_m[[1, 4]]).all()
    # the solver's step tolerance, not its last digits: it stops once a step moves no coordinate by more than 1e-6
    # (rad or m; measured 1e-10), which moves a marker by less than 1e-6 m on this model's < 1 m long legs
    np.testing.assert_allclose(solution.coordinates[[0, 2]], q[[0, 2]], atol=STEP_TOLERANCE)
    assert solution.converged[[0, 2, 3]].all() and not solution.converged[[1, 4]].any()
    assert solution.marker_errors_m[0].max() < STEP_TOLERANCE
    # the planar model cannot follow a marker out of its plane: the fit keeps the pose, the marker its 4 mm
    assert solution.marker_errors_m[3, 2] == pytest.approx(0.004, abs=STEP_TOLERANCE)
    assert np.delete(solution.marker_errors_m[3], 2).max() < STEP_TOLERANCE
    np.testing.assert_allclose(solution.coordinates[3], q[3], atol=STEP_TOLERANCE)
