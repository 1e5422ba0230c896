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
    assert "opensim.coordinate_map.knee_right.sign" in warnings[0]
