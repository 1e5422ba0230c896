"""Inverse kinematics (loper_analysis.motion.ik) against known joint angles and OpenSim's InverseKinematicsTool.

Also the IK task files (loper_analysis.io.ik_tasks), the time chunks of a trial and the joint-angle table.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.ik_tasks import read_ik_tasks
from loper_analysis.io.osim import quiet_opensim, read_model, write_model
from loper_analysis.motion.ik import (
    DEFAULT_COORDINATE_MAP,
    chunk_frames,
    inverse_kinematics,
    join_chunks,
    joint_angle_table,
    marker_positions,
)
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.motion.opensim_ik import markers_table

FS = 128.0
GENERIC_RAJAGOPAL = Path(__file__).resolve().parents[1] / "data" / "rajagopal2016" / "Rajagopal2016.osim"


@pytest.fixture(scope="module")
def model_path(tmp_path_factory):
    return write_model(build_lower_body_model(1.73, 64.9), tmp_path_factory.mktemp("ik") / "model.osim")


@pytest.fixture(scope="module")
def model(model_path):
    return read_model(model_path)


#: The tree solver's step tolerance (rad or m) at which IK is held to recover known angles and join chunks
#: bit-close (the pipeline solves at ``TREE_STEP_TOLERANCE``, 1e-6).
TIGHT_STEP_TOLERANCE = 1e-8


def _truth(n=256):
    t = np.arange(n) / FS
    w = 2 * np.pi * 0.6
    return t, {
        "pelvis_tx": 0.02 * np.sin(2 * w * t),
        "pelvis_ty": 0.93 + 0.01 * np.sin(2 * w * t),
        "pelvis_tilt": 0.05 * np.sin(w * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(w * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_l": 0.1 * np.sin(w * t + 2),
        "hip_flexion_r": 0.1 - 0.3 * np.sin(w * t),
        "knee_flexion_r": 0.6 - 0.5 * np.sin(w * t + 1),
        "ankle_dorsiflexion_r": -0.1 * np.sin(w * t + 2),
    }


@pytest.fixture(scope="module")
def synthetic(model):
    t, truth = _truth()
    return t, truth, marker_positions(model, truth)


def test_marker_positions_hold_length_one_trajectories_and_select_markers(model, synthetic):
    t, truth, X = synthetic
    held = {**truth, "pelvis_ty": truth["pelvis_ty"][:1]}
    expected = marker_positions(model, {**truth, "pelvis_ty": np.full(t.size, truth["pelvis_ty"][0])})
    np.testing.assert_array_equal(marker_positions(model, held), expected)
    picked = ["LHEE", "RASI"]
    np.testing.assert_array_equal(
        marker_positions(model, truth, picked), X[:, [list(MARKERS).index(m) for m in picked]]
    )
    with pytest.raises(LoperInputError, match="length 1 or 256"):
        marker_positions(model, {**truth, "pelvis_ty": truth["pelvis_ty"][:10]})


def test_ik_recovers_known_angles(model, synthetic):
    t, truth, X = synthetic
    res = inverse_kinematics(model, t, X, list(MARKERS), tree_step_tolerance=TIGHT_STEP_TOLERANCE)
    for i, name in enumerate(res.coordinate_names):
        err = np.abs(res.coordinates[:, i] - truth[name]).max()
        assert err < np.deg2rad(0.1) / 10, (name, err)  # well inside the 0.1 deg requirement
    assert np.nanmax(res.marker_rms_m) < 1e-5


def test_missing_marker_frames_are_dropped_not_fatal(model, synthetic):
    t, truth, X = synthetic
    X = X.copy()
    X[50:60, list(MARKERS).index("LKNE")] = np.nan
    res = inverse_kinematics(model, t, X, list(MARKERS))
    k = res.coordinate_names.index("knee_flexion_l")
    np.testing.assert_allclose(res.coordinates[:, k], truth["knee_flexion_l"], atol=1e-4)


def test_marker_errors_equal_the_distances_of_the_solved_pose(model, synthetic):
    """Per-frame RMS and max marker error against forward kinematics of the IK solution; a missing
    marker is left out of its frames (OpenSim reports 0 for it)."""
    t, _, X = synthetic
    noisy = X + np.random.default_rng(7).normal(0.0, 2e-3, X.shape)
    knee = list(MARKERS).index("LKNE")
    noisy[50:60, knee] = np.nan
    res = inverse_kinematics(model, t, noisy, list(MARKERS))
    solved = marker_positions(model, {c: res.coordinates[:, i] for i, c in enumerate(res.coordinate_names)})
    dist = np.linalg.norm(solved - noisy, axis=2)  # NaN where the marker is missing
    np.testing.assert_allclose(res.marker_rms_m, np.sqrt(np.nanmean(dist**2, axis=1)), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(res.marker_max_m, np.nanmax(dist, axis=1), rtol=1e-9, atol=1e-12)
    # 2 mm per axis on 36 markers, 9 coordinates absorb part of it: E[rms^2] = 4e-6 * (3 * 36 - 9) / 36
    assert np.sqrt(np.mean(res.marker_rms_m**2)) == pytest.approx(2e-3 * np.sqrt(99 / 36), rel=0.05)


def test_coordinate_task_locks_the_ankle(model, synthetic):
    t, _, X = synthetic
    weights = {m: (0.0 if m in ("RHEE", "RMT1", "RMT5") else 1.0) for m in MARKERS}
    res = inverse_kinematics(
        model, t, X, list(MARKERS), marker_weights=weights, coordinate_tasks={"ankle_dorsiflexion_r": (1e3, 0.25)}
    )
    k = res.coordinate_names.index("ankle_dorsiflexion_r")
    np.testing.assert_allclose(res.coordinates[:, k], 0.25, atol=1e-3)


@pytest.mark.parametrize("solver", ["tree", "opensim"])
def test_matches_opensims_inverse_kinematics_tool(model_path, model, synthetic, tmp_path, solver):
    osim = quiet_opensim()
    t, _, X = synthetic
    rng = np.random.default_rng(0)
    Xn = X + rng.normal(0, 0.002, X.shape)  # noisy markers: the two must agree on the least-squares answer
    # TRC in mm through OpenSim's own adapter
    table = markers_table(t, Xn * 1000.0, list(MARKERS))
    table.removeTableMetaDataKey("Units")
    table.addTableMetaDataString("Units", "mm")
    table.addTableMetaDataString("DataRate", str(FS))
    table.addTableMetaDataString("CameraRate", str(FS))
    trc = tmp_path / "trial.trc"
    osim.TRCFileAdapter().write(table, str(trc))
    # a task set with marker weights and one coordinate task
    tasks = osim.IKTaskSet()
    weights = {m: (2.0 if m.endswith("ASI") else 1.0) for m in MARKERS}
    for m, w in weights.items():
        mt = osim.IKMarkerTask()
        mt.setName(m)
        mt.setWeight(w)
        tasks.cloneAndAppend(mt)
    ct = osim.IKCoordinateTask()
    ct.setName("ankle_dorsiflexion_r")
    ct.setWeight(10.0)
    ct.setValueType(osim.IKCoordinateTask.ManualValue)
    ct.setValue(0.05)
    tasks.cloneAndAppend(ct)
    tasks_xml = tmp_path / "tasks.xml"
    tasks.printToXML(str(tasks_xml))
    tool = osim.InverseKinematicsTool()
    tool_model = osim.Model(str(model_path))  # keep a reference: the tool does not own it
    tool.setModel(tool_model)
    tool.setMarkerDataFileName(str(trc))
    tool.set_IKTaskSet(osim.IKTaskSet(str(tasks_xml)))
    tool.setStartTime(t[0])
    tool.setEndTime(t[-1])
    tool.set_accuracy(1e-8)
    mot = tmp_path / "tool.mot"
    tool.setOutputMotionFileName(str(mot))
    tool.set_results_directory(str(tmp_path))
    assert tool.run()
    ref = osim.TimeSeriesTable(str(mot))
    in_degrees = ref.getTableMetaDataAsString("inDegrees") == "yes"
    ours_w, ours_c = read_ik_tasks(tasks_xml)
    assert ours_w == weights and ours_c == {"ankle_dorsiflexion_r": (10.0, 0.05)}
    res = inverse_kinematics(
        model,
        t,
        Xn,
        list(MARKERS),
        marker_weights=ours_w,
        coordinate_tasks=ours_c,
        tree_step_tolerance=1e-8,
        opensim_accuracy=1e-8,
        solver=solver,
    )
    assert res.solver == solver
    labels = list(ref.getColumnLabels())
    for i, name in enumerate(res.coordinate_names):
        col = ref.getDependentColumn(name).to_numpy()
        if in_degrees and not name.endswith(("_tx", "_ty")):
            col = np.deg2rad(col)
        assert name in labels
        np.testing.assert_allclose(res.coordinates[:, i], col, atol=1e-6, err_msg=name)


def test_tsv_tasks_and_bad_input(model, synthetic, tmp_path):
    tsv = tmp_path / "tasks.tsv"
    tsv.write_text(
        "name\tkind\tweight\tvalue\nLASI\tmarker\t2\t\nknee_flexion_r\tcoordinate\t5\t0.3\n"
        "ankle_dorsiflexion_r\tcoordinate\t1\t\n"
    )
    w, c = read_ik_tasks(tsv)
    assert w == {"LASI": 2.0} and c == {"knee_flexion_r": (5.0, 0.3), "ankle_dorsiflexion_r": (1.0, None)}
    bad = tmp_path / "bad.tsv"
    bad.write_text("name\tkind\tweight\nLASI\tmarkr\t1\n")
    with pytest.raises(LoperInputError, match="row 1, column kind: 'markr'"):
        read_ik_tasks(bad)
    t, _, X = synthetic
    with pytest.raises(
        LoperInputError, match=r"\['XYZ'\] of the IK tasks are not in .*model\.osim \(model loper_lower_body\)"
    ):
        inverse_kinematics(model, t, X, list(MARKERS), marker_weights={"XYZ": 1.0})
    with pytest.raises(LoperInputError, match=r"\['RASI'\] of the IK tasks are not in the marker data"):
        inverse_kinematics(model, t, X[:, 1:], list(MARKERS)[1:], marker_weights={"LASI": 1.0, "RASI": 1.0})
    with pytest.raises(LoperInputError, match="coordinate task on 'knee_angle_r'"):
        inverse_kinematics(
            model, t, X, list(MARKERS), marker_weights=None, coordinate_tasks={"knee_angle_r": (1.0, None)}
        )


def test_chunks_join_seamlessly(model, synthetic):
    t, _, X = synthetic
    whole = inverse_kinematics(model, t, X, list(MARKERS), tree_step_tolerance=TIGHT_STEP_TOLERANCE).frame()
    parts = []
    for c in range(3):
        sel = chunk_frames(len(t), 3, c)
        parts.append(
            inverse_kinematics(model, t[sel], X[sel], list(MARKERS), tree_step_tolerance=TIGHT_STEP_TOLERANCE).frame()
        )
    assert [len(p) for p in parts] == [85, 86, 85]
    joined = join_chunks(parts)
    np.testing.assert_array_equal(joined.time_s, whole.time_s)
    np.testing.assert_allclose(joined.drop(columns="time_s"), whole.drop(columns="time_s"), atol=1e-7)
    with pytest.raises(LoperInputError, match="chunk 1: starts at t = 0.0000"):
        join_chunks([parts[0], parts[0]])
    with pytest.raises(LoperInputError, match="gap"):
        join_chunks([parts[0], parts[2]])
    with pytest.raises(LoperInputError, match="chunk must lie in 0 .. 2"):
        chunk_frames(10, 3, 3)


def test_joint_angle_table_maps_names_and_signs():
    coords = pd.DataFrame(
        {
            "time_s": [0.0, 0.01],
            "pelvis_tilt": [0.1, 0.2],
            "pelvis_tx": [0.5, 0.6],
            **{c: [0.3, 0.4] for c, _ in list(DEFAULT_COORDINATE_MAP.values())[2:]},
        }
    )
    angles = joint_angle_table(coords)
    np.testing.assert_allclose(angles.pelvis_angle_rad, [-0.1, -0.2])
    np.testing.assert_allclose(angles.knee_left_rad, [0.3, 0.4])
    gait2392 = {
        "pelvis_angle": {"coordinate": "pelvis_tilt", "sign": -1},
        "knee_left": {"coordinate": "knee_angle_l", "sign": -1},
    }
    angles = joint_angle_table(coords.rename(columns={"knee_flexion_l": "knee_angle_l"}), gait2392)
    assert list(angles.columns) == ["time_s", "pelvis_angle_rad", "knee_left_rad"]
    np.testing.assert_allclose(angles.knee_left_rad, [-0.3, -0.4])
    with pytest.raises(LoperInputError, match="coordinate 'knee_angle_l'"):
        joint_angle_table(coords, gait2392, source="trial.mot")


def test_nan_marker_is_left_out_of_its_frames_known_angles(model, synthetic):
    """OpenSim 4.6's MarkersReference drops a NaN marker in its frames: exact markers of known angles with
    LKNE and RHEE missing in some frames give the known angles (measured within 1.1e-8 rad, markers within
    7.6e-10 m, at a tolerance of 1e-10; 8.5e-7 rad at 1e-8)."""
    t, truth, X = synthetic
    X = X.copy()
    X[40:120, list(MARKERS).index("LKNE")] = np.nan
    X[::3, list(MARKERS).index("RHEE")] = np.nan
    res = inverse_kinematics(model, t, X, list(MARKERS), tree_step_tolerance=1e-10)
    for i, name in enumerate(res.coordinate_names):
        err = np.abs(res.coordinates[:, i] - truth[name]).max()
        assert err < 1e-6, (name, err)
    assert np.nanmax(res.marker_max_m) < 1e-6


def test_frames_with_too_few_markers_stop_ik_when_asked(model, synthetic):
    t, _, X = synthetic
    X = X.copy()
    keep = ["LASI", "RASI", "LKNE", "LHEE"]
    X[:, [i for i, m in enumerate(MARKERS) if m not in keep]] = np.nan
    X[100:103, [list(MARKERS).index("LASI"), list(MARKERS).index("LKNE")]] = np.nan
    with pytest.raises(LoperInputError) as err:
        inverse_kinematics(model, t, X, list(MARKERS), min_markers=3, source="walk.trc", sparse_frames="error")
    message = str(err.value)
    assert message.startswith(f"walk.trc: 3 frame(s) hold fewer than 3 of the {len(MARKERS)} weighted markers")
    assert "frames 100..102 (t = 0.7812..0.7969 s); markers missing there: LASI, RPSI, LPSI," in message
    assert message.endswith(", LTHI_AS, and 14 more")  # 34 markers missing in those frames: 20 named
    with pytest.raises(LoperInputError) as err:
        inverse_kinematics(
            model,
            t,
            X,
            list(MARKERS),
            marker_weights={m: 1.0 for m in keep},
            min_markers=3,
            source="walk.trc",
            sparse_frames="error",
        )
    assert str(err.value) == (
        "walk.trc: 3 frame(s) hold fewer than 3 of the 4 weighted markers, too few to solve IK: "
        "frames 100..102 (t = 0.7812..0.7969 s); markers missing there: LASI, LKNE"
    )


def test_frames_outside_the_capture_volume_are_left_out(model, synthetic):
    """An overground trial: no marker at the start, a pelvis with 2 of its 4 markers for a few frames: those
    frames are NaN, the others solved as with every frame present."""
    t, truth, X = synthetic
    X = X.copy()
    X[:10] = np.nan
    X[50:53, [list(MARKERS).index(m) for m in ("RPSI", "LPSI")]] = np.nan  # pelvis placed by the thighs alone
    res = inverse_kinematics(model, t, X, list(MARKERS), tree_step_tolerance=1e-10)
    expected = np.ones(t.size, bool)
    expected[:10] = expected[50:53] = False
    np.testing.assert_array_equal(res.solved, expected)
    assert res.n_left_out == 13 and res.undetermined == {}
    assert np.isnan(res.coordinates[~expected]).all() and np.isnan(res.marker_rms_m[~expected]).all()
    for i, name in enumerate(res.coordinate_names):
        assert np.abs(res.coordinates[expected, i] - truth[name][expected]).max() < 1e-6, name
    summary = res.summary(0.02).iloc[0]
    assert (summary.n_frames, summary.n_frames_solved, summary.n_frames_left_out) == (256, 243, 13)
    assert summary.first_solved_s == t[10] and summary.last_solved_s == t[-1]


def test_a_trial_without_a_frame_to_solve_stops(model, synthetic):
    t, _, X = synthetic
    X = X.copy()
    X[:, [list(MARKERS).index(m) for m in ("RPSI", "LPSI")]] = np.nan
    with pytest.raises(
        LoperInputError,
        match=r"walk\.trc: no frame holds 3 weighted markers with one beyond the "
        r"pelvis: nothing to solve",
    ):
        inverse_kinematics(model, t, X, list(MARKERS), source="walk.trc")


@pytest.mark.parametrize("solver", ["tree", "opensim"])
def test_locked_and_coupled_coordinates_of_rajagopal2016(tmp_path, solver):
    """Rajagopal2016 as distributed: locked subtalar, mtp and wrist angles, patella coupled to the knee."""
    from loper_analysis.io.opensim_tables import read_markers
    from loper_analysis.io.osim import read_marker_set
    from tests.rajagopal_lab import IK_SETUP, MARKER_SET, WALK_TRC

    model = read_model(GENERIC_RAJAGOPAL)
    model.updateMarkerSet(read_marker_set(MARKER_SET))
    t, X, labels = read_markers(WALK_TRC)
    weights, coordinates = read_ik_tasks(IK_SETUP)  # the task set of OpenSim's own IK setup
    assert len(weights) == 39 and weights["R.ASIS"] == 50.0 and coordinates == {}
    res = inverse_kinematics(
        model, t[:20], X[:20], labels, marker_weights=weights, coordinate_tasks=coordinates, solver=solver
    )
    assert res.solver == solver  # the tree holds Rajagopal2016's joints and couplers
    names = res.coordinate_names
    assert len(names) == 39 and res.solved.all()
    for locked in ("subtalar_angle_r", "mtp_angle_l", "wrist_flex_r", "wrist_dev_l"):
        np.testing.assert_array_equal(res.coordinates[:, names.index(locked)], 0.0)  # held at the default
    knee, beta = res.coordinates[:, names.index("knee_angle_r")], res.coordinates[:, names.index("knee_angle_r_beta")]
    np.testing.assert_allclose(beta, knee, atol=1e-8)  # the coupler constraint: beta follows the knee
    assert np.ptp(knee) > 0.05
    with pytest.raises(
        LoperInputError,
        match=r"coordinate task on 'subtalar': not a coordinate of .*Rajagopal2016\.osim "
        r"\(model Rajagopal2016\)",
    ):
        inverse_kinematics(
            model,
            t[:2],
            X[:2],
            labels,
            marker_weights=weights,
            coordinate_tasks={"subtalar": (1.0, None)},
            solver=solver,
        )


def test_a_model_the_tree_does_not_hold_is_solved_by_opensim_and_says_why():
    """A body on a FreeJoint (not in the kinematic tree): the tree solver hands the trial to OpenSim's, and the
    result names the reason; the coordinates are OpenSim's to the last digit."""
    osim = quiet_opensim()
    model = osim.Model()
    body = osim.Body("block", 1.0, osim.Vec3(0), osim.Inertia(0.1))
    model.addBody(body)
    model.addJoint(osim.FreeJoint("free", model.getGround(), body))
    arm = osim.Body("arm", 1.0, osim.Vec3(0), osim.Inertia(0.1))
    model.addBody(arm)
    model.addJoint(osim.PinJoint("pin", body, osim.Vec3(0), osim.Vec3(0), arm, osim.Vec3(0), osim.Vec3(0)))
    places = [(0.1, 0, 0), (0, 0.1, 0), (0, 0, 0.1), (0.1, 0.1, 0.1)]
    for i, p in enumerate(places):
        model.addMarker(osim.Marker(f"M{i}", body, osim.Vec3(*p)))
    model.addMarker(osim.Marker("A", arm, osim.Vec3(0.3, 0, 0)))  # the arm along x, the pin at 0
    model.initSystem()
    t = np.arange(5) / 100.0
    X = np.array([[np.array(p) + [0.01 * k, 0.5, 0.0] for p in [*places, (0.3, 0, 0)]] for k in range(5)])
    labels = [*(f"M{i}" for i in range(4)), "A"]
    ours = inverse_kinematics(model, t, X, labels, solver="tree")
    theirs = inverse_kinematics(model, t, X, labels, solver="opensim")
    assert ours.solver == "opensim" and "joint 'free' is a FreeJoint" in ours.fallback_reason
    assert ours.summary(0.02).solver.iloc[0] == f"opensim: {ours.fallback_reason}"  # the summary names why
    assert theirs.solver == "opensim"
    np.testing.assert_array_equal(ours.coordinates, theirs.coordinates)
    ty = ours.coordinate_names.index("free_coord_4")
    np.testing.assert_allclose(ours.coordinates[:, ty], 0.5, atol=1e-6)  # the block lifted by 0.5 m
