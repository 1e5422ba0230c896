"""The QTM-style lab export (tests/qtm_export.py, tests/lab_export_session.py): a session written to disk and read
back by our readers, by ezc3d's force-platform extraction (child process) and through OpenSim IK."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.device.loadcell import robot_log_frames_and_native
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.robot_log_mat import read_robot_log_mat
from loper_analysis.motion.ik import inverse_kinematics
from loper_analysis.motion.markers import rotate_markers
from loper_analysis.synthetic.trials import LabSettings
from tests.gait2392_models import gait2392_with_markers
from tests.lab_export_session import LabExportFiles, LabExportSettings, lab_export_session
from tests.qtm_export import ROBOT_LOG_MAT_VARIABLES, QTMExportSettings, qtm_walking_export

GAIT2392 = Path(__file__).resolve().parents[1] / "examples" / "gait2392"
FIRST_FRAME = 1000
LAB = LabSettings()

#: ezc3d's force-platform extraction in a process that never loads OpenSim; saves force and COP per plate.
EZC3D_PLATFORMS = """
import sys, numpy as np, ezc3d
c = ezc3d.c3d(sys.argv[1], extract_forceplat_data=True)
np.savez(sys.argv[2], **{f"{k}{i}": p[k].T for i, p in enumerate(c["data"]["platform"])
                         for k in ("force", "moment", "center_of_pressure")})
"""


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    out = tmp_path_factory.mktemp("qtm")
    files = LabExportFiles(
        out,
        GAIT2392 / "gait2392_simbody.osim",
        GAIT2392 / "gait2392_Scale_MarkerSet.xml",
        GAIT2392 / "qtm_label_map.tsv",
    )
    # the default design: no pulses in walk-device, pulses 50 ms after toe-off in pert050-1
    truth = lab_export_session(
        files, "S01", ["walk-device", "pert050-1"], 1.75, 70.0, LabExportSettings(seed=11, walking_duration_s=8.0)
    )
    return out, truth


def test_session_files_and_labels(session):
    out, truth = session
    assert sorted(p.name for p in out.iterdir()) == [
        "pert050-1.c3d",
        "pert050-1.mat",
        "static.c3d",
        "walk-device.c3d",
        "walk-device.mat",
    ]
    rec = read_c3d(out / "walk-device.c3d")
    labels = pd.read_csv(GAIT2392 / "qtm_label_map.tsv", sep="\t")
    assert rec.marker_labels == [f"Subject:{lab}" for lab in labels["label"]] + ["Subject:LBRA_P", "Subject:LBRA_D"]
    assert rec.first_frame == FIRST_FRAME and rec.time_s[0] == FIRST_FRAME / 128.0 == 7.8125
    assert rec.markers_m.shape == (8 * 128, 41, 3)
    for k in (1, 2):
        assert [f"FP{k}_{q}" for q in ("FX", "FY", "FZ", "MX", "MY", "MZ")] == rec.analog_labels[12 * k - 6 : 12 * k]
    assert rec.analog_units[rec.analog_labels.index("FP1_FZ")] == "V"
    # the decoy reads volts, nowhere near the newtons on the belt
    assert np.abs(rec.analog("FP1_FZ")).max() < 10.0 < truth["walk-device"][1].force_n["left"][:, 2].max()
    # long gaps (40 frames) in four markers the fits do not use, short ones elsewhere
    missing = np.isnan(rec.markers_m).any(axis=2).sum(axis=0)
    long = {labels["marker"][i] for i in np.flatnonzero(missing >= 40)}
    assert long == {"Top.Head", "R.Thigh.Rear", "R.Shank.Rear", "R.Midfoot.Lat"}
    static = read_c3d(out / "static.c3d")
    assert static.first_frame == FIRST_FRAME and not np.isnan(static.markers_m).any()


def test_plates_carry_the_synthetic_force_above_the_resting_load(session, tmp_path):
    out, truth = session
    _, exported = truth["walk-device"]
    saved = tmp_path / "plates.npz"
    subprocess.run([sys.executable, "-c", EZC3D_PLATFORMS, str(out / "walk-device.c3d"), str(saved)], check=True)
    plates = np.load(saved)
    for i, side in enumerate(("left", "right")):
        force = plates[f"force{i}"] - exported.resting_force_n[side]
        np.testing.assert_allclose(force, exported.force_n[side], rtol=0, atol=1e-3)  # N, after calibration
        stance = ~np.isnan(exported.cop_m[side][:, 0])
        assert np.median(plates[f"force{i}"][~stance, 2]) == pytest.approx(
            exported.resting_force_n[side][2], abs=1.0
        )  # swing: the plate reads its resting load (not zeroed)
        moment = plates[f"moment{i}"] / 1000.0 - exported.resting_moment_nm[side]  # N·mm -> N·m, about the centre
        centre = np.mean(exported.force_platforms[i].corners_m, axis=0)
        cop = centre[:2] + np.column_stack([-moment[:, 1], moment[:, 0]]) / force[:, 2:3]
        assert stance.mean() == pytest.approx(0.62, abs=0.08)
        np.testing.assert_allclose(cop[stance], exported.cop_m[side][stance, :2], rtol=0, atol=1e-3)  # 1 mm
        # each stance starts under the heel marker as the file holds it (noise 0.5 mm, 1/128 s sampling)
        rec = read_c3d(out / "walk-device.c3d")
        heel = rec.markers_m[:, rec.marker_labels.index("Subject:" + ("L_FCC" if side == "left" else "R_FCC")), :2]
        starts = np.flatnonzero(np.diff(stance.astype(int)) == 1) + 1
        at = np.column_stack([np.interp(rec.analog_time_s[starts], rec.time_s, heel[:, k]) for k in range(2)])
        ok = ~np.isnan(at).any(axis=1)
        assert ok.sum() >= 4
        np.testing.assert_allclose(exported.cop_m[side][starts[ok], :2], at[ok], rtol=0, atol=3e-3)
        # and on its own belt
        y = exported.cop_m[side][stance, 1]
        assert (y > 0).all() if side == "left" else (y < 0).all()


def test_events_are_on_the_file_clock(session):
    out, truth = session
    import ezc3d

    walk, _ = truth["walk-device"]
    ev = ezc3d.c3d(str(out / "walk-device.c3d"))["parameters"]["EVENT"]
    times = 60.0 * np.asarray(ev["TIMES"]["value"][0], float) + np.asarray(ev["TIMES"]["value"][1], float)
    true = walk.mocap_events()
    np.testing.assert_allclose(times, FIRST_FRAME / 128.0 + true["time_s"].to_numpy(), atol=1e-5)
    assert list(ev["CONTEXTS"]["value"]) == [s.capitalize() for s in true["side"]]
    assert set(ev["LABELS"]["value"]) == {"Foot Strike", "Foot Off"}


def test_robot_log_maps_onto_mocap_frames_that_start_at_7_8_s(session):
    out, truth = session
    rec = read_c3d(out / "pert050-1.c3d")
    log, _ = read_robot_log_mat(out / "pert050-1.mat", ROBOT_LOG_MAT_VARIABLES, 1000.0)
    walk, _ = truth["pert050-1"]
    pd.testing.assert_frame_equal(log, walk.robot, check_exact=True, check_dtype=False)
    frames, _ = robot_log_frames_and_native(log, 1000.0, rec.analog(LAB.sync_channel), rec.analog_rate_hz, rec.time_s)
    cm = frames.attrs["clock_map"]
    t_robot = log["time_s"].to_numpy()[::500]
    true_mocap = 7.8125 - LAB.clock_offset_s + (1.0 + 1e-6 * LAB.clock_drift_ppm) * t_robot  # robot clock -> file clock
    np.testing.assert_allclose(cm.to_mocap(t_robot), true_mocap, rtol=0, atol=1e-3)
    assert not frames["force_measured_n"].isna().any()
    # the flag's onsets land within a frame of the scheduled pulse onsets (shifted to the file clock)
    onsets = rec.time_s[np.flatnonzero(np.diff(frames["perturbation"].to_numpy()) == 1) + 1]
    scheduled = 7.8125 + walk.schedule["onset_s"].to_numpy(float)
    assert len(onsets) == len(scheduled) >= 1
    np.testing.assert_allclose(onsets, scheduled, atol=1.5 / 128.0)


def test_ik_of_the_exported_markers_recovers_the_simulated_angles(session):
    out, truth = session
    _, exported = truth["walk-device"]
    rec = read_c3d(out / "walk-device.c3d")
    table = pd.read_csv(GAIT2392 / "qtm_label_map.tsv", sep="\t")
    to_marker = dict(zip(table["label"], table["marker"]))
    labels = [to_marker.get(lab.removeprefix("Subject:"), lab.removeprefix("Subject:")) for lab in rec.marker_labels]
    frames = slice(128, 128 + 3 * 128, 4)  # 3 s at 32 Hz
    X = rotate_markers(rec.markers_m[frames], LAB.lab_to_model_rotation_deg)
    ik = inverse_kinematics(gait2392_with_markers(), rec.time_s[frames], X, labels).frame()
    true = exported.coordinates.iloc[frames]
    for name in ("hip_flexion", "knee_angle", "ankle_angle"):
        for s in "lr":
            error = np.degrees(np.abs(ik[f"{name}_{s}"].to_numpy() - true[f"{name}_{s}"].to_numpy()))
            assert error.max() < 1.0, (f"{name}_{s}", error.max())
    assert np.degrees(np.ptp(true["knee_angle_l"])) > 40.0  # real walking, not a still pose


def test_walking_export_is_deterministic(session):
    _, truth = session
    walk, first = truth["walk-device"]
    model = gait2392_with_markers()
    label_map = dict(zip(*pd.read_csv(GAIT2392 / "qtm_label_map.tsv", sep="\t")[["marker", "label"]].T.to_numpy()))
    a = qtm_walking_export(model, walk, label_map, 70.0, LAB, 3, QTMExportSettings())
    b = qtm_walking_export(model, walk, label_map, 70.0, LAB, 3, QTMExportSettings())
    np.testing.assert_array_equal(a.recording.markers_m, b.recording.markers_m)
    np.testing.assert_array_equal(a.recording.analogs, b.recording.analogs)
    assert not np.array_equal(a.recording.analogs, first.recording.analogs)  # another seed, other noise
