"""The scale report's checks: a static pose beyond 15 degrees or away from the lab's own, neighbouring bodies
scaled unlike each other; the report of one run of ScaleTool, with a marker of known offset."""

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


def test_a_static_pose_beyond_its_joints_limit_and_one_away_from_the_lab_are_warned_about():
    """Hip beyond 40 degrees, knee beyond 25, ankle beyond 15; hip and knee 5 degrees from the lab's, ankle 10."""
    pose = {"hip_left": np.radians(-42.0), "knee_left": np.radians(12.0), "ankle_left": np.radians(16.0)}
    lab = {"hip_left": np.radians(-38.0), "knee_left": np.radians(6.5), "ankle_left": np.radians(7.0)}
    warnings = dict(static_pose_warnings(pose, lab))
    assert sorted(warnings) == ["static_pose_ankle_left", "static_pose_hip_left", "static_pose_knee_left_lab"]
    assert "hip_left -42.0 deg, beyond +-40 deg" in warnings["static_pose_hip_left"]
    assert "ankle_left +16.0 deg, beyond +-15 deg" in warnings["static_pose_ankle_left"]
    assert "offset of +5.5 deg" in warnings["static_pose_knee_left_lab"]
    assert "model.scale_setup" in warnings["static_pose_hip_left"]
    assert static_pose_warnings({"knee_right": np.radians(24.9), "hip_right": np.radians(39.9)}) == []
    assert static_pose_warnings({"knee_right": np.radians(4.0)}, {"knee_right": np.radians(-0.9)}) == []


def test_neighbouring_factors_more_than_20_percent_apart_are_warned_about():
    factors = {"tibia_r": (1.09,) * 3, "talus_r": (1.09,) * 3, "calcn_r": (1.33,) * 3, "femur_r": (1.0,) * 3}
    pairs = [("femur_r", "tibia_r"), ("tibia_r", "talus_r"), ("talus_r", "calcn_r"), ("pelvis", "femur_r")]
    warnings = neighbour_factor_warnings(factors, pairs)
    assert [name for name, _ in warnings] == ["scale_talus_r_calcn_r"]
    assert "differ by 22 %: talus_r 1.090, calcn_r 1.330" in warnings[0][1]
    assert "a marker of the measurement placed elsewhere" in warnings[0][1]


def test_neighbours_both_scaled_between_joint_centres_are_said_to_differ_in_proportion():
    """A child's pelvis (hip centres 107 mm apart: 0.643 of gait2392's) on a femur of 0.992: the factors differ
    by 54 %, from the subject's proportions, not a marker placed elsewhere; a foot measured by its markers next to
    a talus scaled between centres keeps the marker's wording."""
    factors = {"pelvis": (0.643,) * 3, "femur_r": (0.992,) * 3, "talus_r": (0.907,) * 3, "calcn_r": (0.535,) * 3}
    pairs = [("pelvis", "femur_r"), ("talus_r", "calcn_r")]
    warnings = dict(neighbour_factor_warnings(factors, pairs, {"pelvis", "femur_r", "talus_r"}))
    assert "differ by 54 %" in warnings["scale_pelvis_femur_r"]
    assert "both between the static trial's joint centres" in warnings["scale_pelvis_femur_r"]
    assert "a marker of the measurement placed elsewhere" in warnings["scale_talus_r_calcn_r"]


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


OFFSET_M = np.array([0.0, 0.0, 0.02])


@pytest.fixture(scope="module")
def standing():
    """The generated model of a 1.85 m subject, 20 frames (128 Hz) of its markers standing, and the same model with
    RASI placed 20 mm lateral of where the subject's is."""
    from loper_analysis.io.osim import quiet_opensim
    from loper_analysis.motion.ik import marker_positions
    from loper_analysis.motion.model import MARKERS, build_lower_body_model
    from loper_analysis.motion.static_trial import StaticPose

    osim = quiet_opensim()
    model, moved = build_lower_body_model(1.85, 80.0), build_lower_body_model(1.85, 80.0)
    marker = moved.getMarkerSet().get("RASI")
    marker.set_location(osim.Vec3(*(marker.get_location().to_numpy() + OFFSET_M)))
    t = np.arange(20) / 128.0
    X = marker_positions(model, {"pelvis_ty": np.full(t.size, 0.98)})
    return model, moved, StaticPose(t, X, list(MARKERS), {}, [], {})


def _run(scaled, unplaced, tasks, window):
    from loper_analysis.io.scale_tool import ScaleToolRun

    return ScaleToolRun(b"", scaled, unplaced, {"pelvis": (1.1, 1.1, 1.1)}, tasks, window)


def test_a_runs_report_gives_a_moved_markers_offset_and_the_lab_angles_of_its_window(standing):
    from loper_analysis.motion.model_settings import ModelSettings
    from loper_analysis.motion.scale_report import scale_run_report

    model, moved, pose = standing
    weights = {m: 1e-6 if m == "RASI" else 1.0 for m in pose.labels}  # RASI barely pulls: the pose stays exact
    run = _run(moved, model, (weights, {}), (pose.time_s[0], pose.time_s[9]))
    lab = pd.DataFrame({"time_s": pose.time_s, "hip_left_rad": np.linspace(0.0, 0.19, 20)})
    subject = (80.0, 1.5, "mass: given; height: given", 1.85)
    table = scale_run_report(run, model, pose, subject, ModelSettings(), lab_labels={"RASI": "S:RASI"}, lab_angles=lab)
    markers = table[table.kind == "marker"].set_index("name")
    np.testing.assert_allclose(markers.loc["RASI", "marker_error_m"], 0.02, atol=1e-4)
    assert markers.drop(index="RASI")["marker_error_m"].max() < 1e-4
    assert markers["marker_error_before_m"].max() < 1e-4  # the unplaced model's RASI is the subject's
    assert markers.loc["RASI", "label"] == "S:RASI" and markers.loc["RASI", "marker_weight"] == 1e-6
    hip = table[(table.kind == "pose") & (table.name == "hip_left")].iloc[0]
    assert abs(hip.angle_rad) < 1e-4 and hip.lab_angle_rad == pytest.approx(0.045, abs=1e-15)
    assert table[table.kind == "warning"].name.tolist() == ["stature"]  # 1.85 m where 1.5 m is given
    assert table[table.kind == "subject"][["mass_kg", "height_m"]].values.tolist() == [[80.0, 1.5]]
    bodies = table[table.kind == "body"].set_index("name")
    assert bodies.loc["pelvis", "scale_factor_y"] == 1.1 and bodies.loc["thigh_l", "scale_factor_y"] == 1.0


def test_placement_without_scaling_takes_the_generic_markers_as_the_ones_placed(standing):
    from loper_analysis.motion.model_settings import ModelSettings
    from loper_analysis.motion.scale_report import scale_run_report

    model, moved, pose = standing
    weights = {m: 1e-6 if m == "RASI" else 1.0 for m in pose.labels}
    subject = (80.0, 1.85, "mass: given; height: given", 1.85)
    window = (pose.time_s[0], pose.time_s[-1])
    placed = scale_run_report(_run(model, None, (weights, {}), window), moved, pose, subject, ModelSettings())
    fits = placed[placed.kind == "markers"].set_index("name")
    assert list(fits.index) == ["before placement", "after placement"]
    np.testing.assert_allclose(fits.loc["before placement", "marker_error_max_m"], 0.02, atol=1e-4)  # the generic
    assert fits.loc["before placement", "worst_marker"] == "RASI"
    scaled_only = scale_run_report(_run(model, None, None, window), moved, pose, subject, ModelSettings())
    assert scaled_only[scaled_only.kind == "markers"].name.tolist() == ["after scaling"]
