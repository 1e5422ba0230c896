"""The lab's own joint angles read from its file, and our agreement with them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.lab_angles import lab_agreement, lab_joint_angles
from loper_analysis.motion.plausibility import inverted_knee_warnings

QCMAS = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "QCMAS"


def test_plug_in_gait_angles_of_the_walk_are_read_in_rad():
    rec = read_c3d(QCMAS / "walk-nodevice.c3d")
    table, used = lab_joint_angles(rec.time_s, rec.output_labels, rec.output_kinds, rec.outputs, "deg")
    assert used["knee_left"] == "LKneeAngles_M" and used["pelvis_angle"] == "LPelvisAngles_M"
    assert list(table.columns) == ["time_s", "pelvis_angle_rad", "hip_left_rad", "knee_left_rad", "ankle_left_rad",
                                   "hip_right_rad", "knee_right_rad", "ankle_right_rad"]  # fmt: skip
    raw = rec.outputs[:, rec.output_labels.index("LKneeAngles_M"), 0]
    np.testing.assert_allclose(table["knee_left_rad"], np.radians(raw))
    assert table["time_s"].iloc[0] == pytest.approx(2.27)


def test_the_static_prefers_the_unsuffixed_label():
    rec = read_c3d(QCMAS / "static.c3d")
    _, used = lab_joint_angles(rec.time_s, rec.output_labels, rec.output_kinds, rec.outputs, "deg")
    assert used["hip_left"] == "LHipAngles"


def test_agreement_of_an_offset_copy_and_of_an_inverted_one():
    t = np.arange(200) / 100.0
    lab = pd.DataFrame({"time_s": t, "knee_left_rad": 0.5 * (1 - np.cos(2 * np.pi * t)), "hip_left_rad": np.sin(t)})
    ours = lab.copy()
    ours["knee_left_rad"] += 0.1
    ours["hip_left_rad"] *= -1
    table = lab_agreement(ours.iloc[5:], lab).set_index("angle")
    knee, hip = table.loc["knee_left"], table.loc["hip_left"]
    assert knee.n_frames == 195 and knee.r == pytest.approx(1.0)
    assert knee.rms_diff_rad == pytest.approx(0.1) and knee.mean_offset_rad == pytest.approx(0.1)
    assert knee.warning == ""
    assert hip.r == pytest.approx(-1.0) and "anticorrelated" in hip.warning and "r -1.00 < 0.9" in hip.warning


def test_a_knee_flexing_negative_is_warned_about_and_a_walking_knee_is_not():
    t = np.linspace(0, 1, 101)
    knee = np.radians(5 + 55 * np.sin(np.pi * t) ** 4 - 8)  # -3 .. 52 deg
    angles = pd.DataFrame({"knee_left_rad": knee, "knee_right_rad": -knee})
    warnings = inverted_knee_warnings(angles)
    assert len(warnings) == 1 and warnings[0].startswith("knee_right flexes negative (from -52 to 3 deg)")
    assert "ik.coordinate_map.knee_right.sign" in warnings[0]


def test_angles_with_any_suffix_are_read_and_a_missing_one_is_logged(caplog):
    t = np.arange(5) / 100.0
    labels = ["LHipAnglesV", "LKneeAngles_M", "LAnkleAngles", "LPelvisAngles_M", "RHipAngles"]
    values = np.zeros((5, len(labels), 3))
    values[:, 0, 0] = 30.0
    values[:, 4, 0] = np.nan  # stored, but without a number
    with caplog.at_level("INFO", logger="loper_analysis.motion.lab_angles"):
        table, used = lab_joint_angles(t, labels, ["ANGLES"] * len(labels), values, "deg", "walk.c3d")
    assert used == {
        "pelvis_angle": "LPelvisAngles_M",
        "hip_left": "LHipAnglesV",
        "knee_left": "LKneeAngles_M",
        "ankle_left": "LAnkleAngles",
    }
    np.testing.assert_allclose(table["hip_left_rad"], np.radians(30.0))
    assert "hip_right (RHipAngles holds no number)" in caplog.text
    assert "knee_right (no ANGLES point RKneeAngles (with or without a suffix))" in caplog.text


def test_a_comparison_left_out_says_why(caplog):
    t = np.arange(50) / 100.0
    ours = pd.DataFrame({"time_s": t, "knee_left_rad": np.sin(t), "hip_left_rad": np.cos(t)})
    with caplog.at_level("INFO", logger="loper_analysis.motion.lab_angles"):
        assert lab_agreement(ours, pd.DataFrame({"time_s": t})).empty
        table = lab_agreement(ours, ours[["time_s", "knee_left_rad"]].iloc[:5])
    assert "the lab's file stores none of them" in caplog.text
    assert "(the lab's file lacks them): hip_left" in caplog.text
    assert "knee_left not compared with the lab's own angle: 5 frame(s) in common, fewer than 10" in caplog.text
    assert np.isnan(table.loc[0, "r"])


def test_a_constant_offset_at_the_hip_or_knee_is_warned_about_before_the_rms_limit():
    """Ours = the lab's + a constant: 6.5 degrees at the knee is warned about (r 1, RMS 6.5 < 10), 5.5 is not; the
    ankle's offset alone is not judged (Plug-in Gait's tibial torsion and foot options move it)."""
    t = np.arange(100) / 100.0
    lab = pd.DataFrame({"time_s": t, "knee_left_rad": 0.6 * np.sin(2 * np.pi * t) + 0.5})
    lab["ankle_left_rad"] = lab["knee_left_rad"] / 3.0
    for offset_deg, warned in ((6.5, True), (5.5, False)):
        ours = lab.copy()
        ours["knee_left_rad"] += np.radians(offset_deg)
        ours["ankle_left_rad"] += np.radians(offset_deg)
        table = lab_agreement(ours, lab).set_index("angle")
        assert table.loc["knee_left", "rms_diff_rad"] == pytest.approx(np.radians(offset_deg))
        assert ("mean offset" in table.loc["knee_left", "warning"]) is warned
        assert table.loc["ankle_left", "warning"] == ""
