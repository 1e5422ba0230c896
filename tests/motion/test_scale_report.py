"""The scale report's checks: a static pose beyond 15 degrees or away from the lab's own, neighbouring bodies
scaled unlike each other."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.motion.scale_report import (
    StaticFit,
    neighbour_factor_warnings,
    scale_report,
    static_pose_warnings,
)


def test_a_static_pose_beyond_15_degrees_and_one_away_from_the_lab_are_warned_about():
    pose = {"hip_left": np.radians(-22.0), "knee_left": np.radians(12.0), "ankle_left": np.radians(3.0)}
    lab = {"hip_left": np.radians(0.0), "knee_left": np.radians(-8.0), "ankle_left": np.radians(1.0)}
    warnings = dict(static_pose_warnings(pose, lab))
    assert sorted(warnings) == ["static_pose_hip_left", "static_pose_hip_left_lab", "static_pose_knee_left_lab"]
    assert "hip_left -22.0 deg, beyond +-15 deg" in warnings["static_pose_hip_left"]
    assert "offset of +20.0 deg" in warnings["static_pose_knee_left_lab"]
    assert "opensim.scale_setup" in warnings["static_pose_hip_left"]
    assert static_pose_warnings({"knee_right": np.radians(14.9)}) == []


def test_neighbouring_factors_more_than_20_percent_apart_are_warned_about():
    factors = {"tibia_r": (1.09,) * 3, "talus_r": (1.09,) * 3, "calcn_r": (1.33,) * 3, "femur_r": (1.0,) * 3}
    pairs = [("femur_r", "tibia_r"), ("tibia_r", "talus_r"), ("talus_r", "calcn_r"), ("pelvis", "femur_r")]
    warnings = neighbour_factor_warnings(factors, pairs)
    assert [name for name, _ in warnings] == ["scale_talus_r_calcn_r"]
    assert "differ by 22 %: talus_r 1.090, calcn_r 1.330" in warnings[0][1]


def test_the_report_holds_the_errors_before_and_after_placement_and_the_pose():
    before = StaticFit({"LKNE": 0.03, "LTHI": 0.09}, {"knee_left": -0.07})
    after = StaticFit({"LKNE": 0.027, "LTHI": 0.001}, {"knee_left": -0.069})
    table = scale_report(
        ["femur_l"], {"femur_l": (1.07, 1.07, 1.07)}, {"LKNE": 10.0, "LTHI": 1.0}, after, before, 100,
        (72.2, 1.86, "mass: plates; height: file"), lab_angles_rad={"knee_left": -0.14},
        warnings=[("w", "text")],
    )  # fmt: skip
    fits = table[table.kind == "markers"].set_index("name")
    assert fits.loc["before placement", "marker_error_rms_m"] == np.sqrt((0.03**2 + 0.09**2) / 2)
    assert (
        fits.loc["before placement", "worst_marker"] == "LTHI" and fits.loc["after placement", "worst_marker"] == "LKNE"
    )
    markers = table[table.kind == "marker"].set_index("name")
    assert markers.loc["LTHI", ["marker_error_before_m", "marker_error_m"]].tolist() == [0.09, 0.001]
    pose = table[table.kind == "pose"].iloc[0]
    assert (pose["name"], pose.angle_rad, pose.lab_angle_rad) == ("knee_left", -0.07, -0.14)  # before placement
    assert table[table.kind == "warning"].source.tolist() == ["text"]
    assert pd.isna(table[table.kind == "subject"].iloc[0].scale_factor_x)


def test_a_model_far_from_the_given_height_is_warned_about():
    from loper_analysis.motion.scale_report import MAX_STATURE_CHANGE, stature_change, stature_warnings

    assert stature_change(1.80, 1.62) == pytest.approx(-0.1)
    assert stature_warnings(1.80, 1.80 * (1 + 0.99 * MAX_STATURE_CHANGE), "given") == []
    [(name, text)] = stature_warnings(1.80, 1.50, "given")
    assert name == "stature"
    assert "1.50 m tall where the subject's height is 1.80 m (given; -17 %" in text and "height_m" in text
    assert stature_warnings(1.80, float("nan"), "given") == []
