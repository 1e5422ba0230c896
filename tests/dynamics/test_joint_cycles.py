"""Our joints' moments and powers: signs and per-kg values in the sense of our angles, the strides cut in their
leg's valid times, their mean and SD."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.dynamics.inverse_dynamics import coordinate_speeds, generalized_forces
from loper_analysis.dynamics.joint_cycles import (
    CYCLE_COLUMNS,
    SUMMARY_COLUMNS,
    cycle_summary,
    joint_coordinates,
    joint_cycles,
    leg_moments,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import read_model
from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP, joint_angle_table

ROOT = Path(__file__).resolve().parents[2]
GAIT2392 = ROOT / "src/loper_analysis/templates/gait2392_simbody.osim"
#: gait2392's map (its knee angle is negative in flexion), as ``inspect`` writes it for a Plug-in Gait lab.
GAIT2392_MAP = {
    "hip_left": {"coordinate": "hip_flexion_l", "sign": 1},
    "knee_left": {"coordinate": "knee_angle_l", "sign": -1},
    "ankle_left": {"coordinate": "ankle_angle_l", "sign": 1},
    "hip_right": {"coordinate": "hip_flexion_r", "sign": 1},
    "knee_right": {"coordinate": "knee_angle_r", "sign": -1},
    "ankle_right": {"coordinate": "ankle_angle_r", "sign": 1},
}
MASS_KG = 72.5
RATE_HZ = 100.0


@pytest.fixture(scope="module")
def swing():
    """gait2392 swinging its legs through known angles (no ground load): moments, speeds, our angles."""
    model = read_model(GAIT2392)
    t = np.arange(120) / RATE_HZ
    w = 2 * np.pi * 0.9
    coords = pd.DataFrame(
        {
            "pelvis_ty": np.full(t.size, 0.95),
            "hip_flexion_l": 0.2 + 0.4 * np.sin(w * t),
            "knee_angle_l": -0.6 - 0.5 * np.sin(w * t + 1.0),
            "ankle_angle_l": 0.1 * np.sin(w * t + 2.0),
            "hip_flexion_r": 0.2 - 0.4 * np.sin(w * t),
            "knee_angle_r": -0.6 + 0.5 * np.sin(w * t + 1.0),
            "ankle_angle_r": -0.1 * np.sin(w * t + 2.0),
        }
    )
    forces = generalized_forces(model, t, coords, cutoff_hz=None)
    speeds = coordinate_speeds(model, t, coords, cutoff_hz=None)
    angles = joint_angle_table(coords.assign(time_s=t), GAIT2392_MAP)
    return t, forces, speeds, angles


def test_power_is_moment_times_our_angular_velocity(swing):
    t, forces, speeds, angles = swing
    table = leg_moments(forces, speeds, GAIT2392_MAP, MASS_KG)
    for key, entry in GAIT2392_MAP.items():
        joint, side = key.split("_")
        sign, coordinate = entry["sign"], entry["coordinate"]
        moment = table[f"{joint}_{side}_moment_nm"].to_numpy()
        # signed as our angle: the coordinate's generalised force times the map's sign
        np.testing.assert_array_equal(moment, sign * forces[f"{coordinate}_moment_nm"].to_numpy())
        np.testing.assert_allclose(table[f"{joint}_{side}_moment_nm_per_kg"], moment / MASS_KG, rtol=1e-15)
        # our angle's speed (the spline's, signed) and its finite difference agree: the power is M(ours) × ω(ours)
        ours_speed = sign * speeds[coordinate].to_numpy()
        np.testing.assert_allclose(
            ours_speed[5:-5], np.gradient(angles[f"{key}_rad"].to_numpy(), t)[5:-5], rtol=0, atol=0.02
        )
        np.testing.assert_allclose(
            table[f"{joint}_{side}_power_w_per_kg"], moment * ours_speed / MASS_KG, rtol=1e-12, atol=1e-15
        )
    # over a swing the knee both generates and absorbs energy
    knee = table["knee_left_power_w_per_kg"].to_numpy()
    assert knee.min() < -0.01 and knee.max() > 0.01
    # the maps' two forms: (coordinate, sign) pairs and {coordinate, sign} mappings
    assert joint_coordinates(DEFAULT_COORDINATE_MAP)[("left", "knee")] == ("knee_flexion_l", 1.0)
    assert joint_coordinates(GAIT2392_MAP)[("left", "knee")] == ("knee_angle_l", -1.0)


def test_valid_columns_and_refusals(swing):
    t, forces, speeds, _ = swing
    table = leg_moments(forces, speeds, GAIT2392_MAP, MASS_KG, {"left": t < 0.5, "right": t >= 0.5})
    assert list(table.columns[-2:]) == ["valid_left", "valid_right"] and table["valid_left"].sum() == 50
    with pytest.raises(LoperInputError, match="mass_kg"):
        leg_moments(forces, speeds, GAIT2392_MAP, 0.0)
    with pytest.raises(LoperInputError, match="sign"):
        leg_moments(forces, speeds, {"knee_left": ("knee_angle_l", 2)}, MASS_KG)
    with pytest.raises(LoperInputError, match="knee_flexion_l"):
        leg_moments(forces, speeds, DEFAULT_COORDINATE_MAP, MASS_KG)


def _linear_moments(t: np.ndarray) -> pd.DataFrame:
    """A moments table whose every column is linear in time (exact under linear resampling)."""
    out = {"time_s": t}
    for k, (side, joint) in enumerate((s, j) for s in ("left", "right") for j in ("hip", "knee", "ankle")):
        out[f"{joint}_{side}_moment_nm"] = 10.0 * (k + 1) * t
        out[f"{joint}_{side}_moment_nm_per_kg"] = (k + 1) * t
        out[f"{joint}_{side}_power_w_per_kg"] = -(k + 1) * t
    return pd.DataFrame(out)


def test_only_strides_in_their_legs_valid_times_are_cut():
    t = np.arange(0, 501) / RATE_HZ
    moments = _linear_moments(t)
    strides = pd.DataFrame(
        {
            "stride": [0, 1, 2, 0],
            "side": ["left", "left", "left", "right"],
            "heel_strike_s": [0.5, 1.6, 2.7, 1.0],
            "end_s": [1.6, 2.7, 3.8, 2.1],
            "removed": [False, True, False, False],
        }
    )
    intervals = {"left": np.array([[0.4, 3.0], [3.1, 4.0]]), "right": np.array([[0.9, 2.2]])}
    cycles = joint_cycles(moments, strides, intervals, n_points=11)
    assert list(cycles.columns) == list(CYCLE_COLUMNS)
    # left stride 1 removed, stride 2 across the gap 3.0 .. 3.1: only left 0 and right 0
    assert sorted(set(zip(cycles["side"], cycles["stride"]))) == [("left", 0), ("right", 0)]
    left_hip = cycles[(cycles["side"] == "left") & (cycles["joint"] == "hip")]
    np.testing.assert_allclose(left_hip["percent_cycle"], np.linspace(0, 100, 11))
    np.testing.assert_allclose(left_hip["moment_nm_per_kg"], np.linspace(0.5, 1.6, 11), rtol=1e-12)
    np.testing.assert_allclose(left_hip["moment_nm"], 10 * np.linspace(0.5, 1.6, 11), rtol=1e-12)
    right_ankle = cycles[(cycles["side"] == "right") & (cycles["joint"] == "ankle")]
    np.testing.assert_allclose(right_ankle["power_w_per_kg"], -6 * np.linspace(1.0, 2.1, 11), rtol=1e-12)
    # no valid time: an empty table with the columns
    empty = joint_cycles(moments, strides, {"left": np.empty((0, 2)), "right": np.empty((0, 2))})
    assert empty.empty and list(empty.columns) == list(CYCLE_COLUMNS)
    assert cycle_summary(empty).empty and list(cycle_summary(empty).columns) == list(SUMMARY_COLUMNS)


def test_the_summary_is_the_mean_and_sd_across_strides():
    t = np.arange(0, 501) / RATE_HZ
    moments = _linear_moments(t)
    strides = pd.DataFrame(
        {"stride": [0, 1], "side": ["left", "left"], "heel_strike_s": [0.5, 1.5], "end_s": [1.5, 2.5]}
    )
    cycles = joint_cycles(moments, strides, {"left": np.array([[0.0, 5.0]])}, n_points=5)
    summary = cycle_summary(cycles)
    assert list(summary.columns) == list(SUMMARY_COLUMNS) and (summary["n_strides"] == 2).all()
    knee = summary[summary["joint"] == "knee"]
    # the two strides are the line 2 t over 0.5 .. 1.5 and 1.5 .. 2.5: mean 2 (t + 0.5), SD 2 × 1 / sqrt(2)
    np.testing.assert_allclose(knee["moment_nm_per_kg_mean"], 2 * (np.linspace(0.5, 1.5, 5) + 0.5), rtol=1e-12)
    np.testing.assert_allclose(knee["moment_nm_per_kg_sd"], np.sqrt(2.0), rtol=1e-12)
