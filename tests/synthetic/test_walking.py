"""Synthetic walking trials: stride statistics, event timing, joint-angle shapes, continuity and feet on the floor."""

from __future__ import annotations

import itertools

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.model import COORDINATES
from loper_analysis.synthetic.gait_curves import NominalGait
from loper_analysis.synthetic.walking import (
    TRUE_EVENT_COLUMNS,
    leg_length_from_height,
    pelvis_height_m,
    walking_kinematics,
)
from tests.synthetic.gait_events import event_times, stances

FS = 128.0
MASS = 70.0
GAIT = NominalGait()
STRIDE = 60.0 / 36.0


@pytest.fixture(scope="module")
def long_trial():
    """10 min at 128 Hz: about 360 strides per leg."""
    return walking_kinematics(600.0, FS, GAIT, np.random.default_rng(20240611), timing_cv=0.03, amplitude_cv=0.05)


# --------------------------------------------------------------------------- timing


def test_stride_duration_mean_and_cv(long_trial):
    _, events = long_trial
    hs = event_times(events, "right", "heel_strike")
    strides = np.diff(hs)
    n = strides.size
    assert n > 350
    # mean: SE = 0.03 * 1.667 / sqrt(n) = 2.6 ms; allow 4 SE
    se_mean = 0.03 * STRIDE / np.sqrt(n)
    assert abs(strides.mean() - STRIDE) < 4 * se_mean
    # CV: SE of a sample CV (normal data) ~ CV / sqrt(2 n) = 0.0011; allow 4 SE
    cv = strides.std(ddof=1) / strides.mean()
    assert abs(cv - 0.03) < 4 * 0.03 / np.sqrt(2 * n)


def test_left_heel_strike_half_a_stride_after_right_and_toe_off_at_stance_fraction(long_trial):
    _, events = long_trial
    r = event_times(events, "right", "heel_strike")
    for side, event, shift, target in (("left", "heel_strike", 0.0, 0.5), ("right", "toe_off", 0.0, 0.65)):
        t = event_times(events, side, event)
        k = np.searchsorted(r, t) - 1
        ok = (k >= 0) & (k + 1 < r.size)
        rel = (t[ok] - r[k[ok]]) / (r[k[ok] + 1] - r[k[ok]]) - shift
        # exact on average; the C1 phase interpolation moves single events by < 1.5 % of a stride
        assert abs(rel.mean() - target) < 0.002
        assert np.max(np.abs(rel - target)) < 0.015
    # events alternate per side and lie inside the trial
    for side in ("left", "right"):
        kinds = events.loc[events["side"] == side, "event"].tolist()
        assert all(a != b for a, b in itertools.pairwise(kinds))
    assert events["time_s"].between(0, 600).all() and events["time_s"].is_monotonic_increasing
    assert list(events.columns) == list(TRUE_EVENT_COLUMNS)


def test_trial_toe_offs_follow_a_warped_stance_fraction():
    """With stance fraction 0.6 the toe-offs come at 0.6 strides, and the knee there is the curves' toe-off value
    (38 deg)."""
    g = NominalGait(stance_fraction=0.6)
    coords, events = walking_kinematics(20.0, 1024.0, g, np.random.default_rng(0), timing_cv=0.0, amplitude_cv=0.0)
    hs, to = event_times(events, "right", "heel_strike"), event_times(events, "right", "toe_off")
    to = to[to > hs[0]][: hs.size - 1]
    np.testing.assert_allclose((to - hs[: to.size]) / STRIDE, 0.6, atol=1e-9)
    knee_at_to = np.interp(to, coords["time_s"], coords["knee_flexion_r"])
    np.testing.assert_allclose(np.rad2deg(knee_at_to), 38.0, atol=0.5)


# --------------------------------------------------------------------------- angles


def test_coordinate_frame_layout(long_trial):
    coords, _ = long_trial
    assert list(coords.columns) == ["time_s", *COORDINATES]
    assert len(coords) == 600 * 128
    np.testing.assert_allclose(np.diff(coords["time_s"]), 1 / FS, rtol=1e-9)
    assert np.all(np.isfinite(coords.to_numpy()))


def test_joint_angle_ranges_per_stride(long_trial):
    coords, events = long_trial
    t = coords["time_s"].to_numpy()
    for side, s in (("right", "r"), ("left", "l")):
        hs = event_times(events, side, "heel_strike")
        hip = np.rad2deg(coords[f"hip_flexion_{s}"].to_numpy())
        knee = np.rad2deg(coords[f"knee_flexion_{s}"].to_numpy())
        ankle = np.rad2deg(coords[f"ankle_dorsiflexion_{s}"].to_numpy())
        hip_range, knee_peak, ankle_min, ankle_max = [], [], [], []
        for a, b in itertools.pairwise(hs):
            sel = (t >= a) & (t < b)
            hip_range.append(np.ptp(hip[sel]))
            knee_peak.append(knee[sel].max())
            ankle_min.append(ankle[sel].min())
            ankle_max.append(ankle[sel].max())
        hip_range, knee_peak = np.array(hip_range), np.array(knee_peak)
        assert 33 < hip_range.mean() < 39 and np.all((hip_range > 28) & (hip_range < 44))
        assert 58 < knee_peak.mean() < 62 and np.all((knee_peak > 52) & (knee_peak < 68))
        assert -15 < np.mean(ankle_min) < -11 and 8 < np.mean(ankle_max) < 12
        # amplitude variation is there: about amplitude_cv of the excursion (5 % of ~36 deg = 1.8 deg)
        assert 1.0 < hip_range.std() < 3.0


def test_pelvis(long_trial):
    coords, _ = long_trial
    tilt = np.rad2deg(coords["pelvis_tilt"].to_numpy())
    np.testing.assert_allclose([tilt.min(), tilt.max()], [-12, -8], atol=0.01)
    np.testing.assert_allclose(np.ptp(coords["pelvis_ty"]), 0.02, atol=1e-4)
    np.testing.assert_allclose(coords["pelvis_ty"].mean(), pelvis_height_m(GAIT), atol=2e-4)
    assert abs(coords["pelvis_tx"].mean()) < 1e-3 and np.ptp(coords["pelvis_tx"]) < 0.021


def test_no_jumps_and_no_kinks(long_trial):
    """Differences bounded by the nominal curve's slope and curvature (x 1.5 for stride and amplitude variation).

    An amplitude switch at a stride boundary (5 % of a 0.6 rad excursion, 0.03
    rad) would break the second-difference bound (about 0.007 rad for the
    knee at 128 Hz) four times over; so would a velocity step of 5 %.
    """
    coords, _ = long_trial
    phase = np.linspace(0.0, 1.0, 20001)
    dt = 1 / FS
    for joint in ("hip_flexion", "knee_flexion", "ankle_dorsiflexion"):
        f = GAIT.joint_series(joint)
        d1 = np.abs(f.derivative(phase)).max() / STRIDE * dt
        d2 = np.abs(np.gradient(f.derivative(phase), phase)).max() / STRIDE**2 * dt**2
        for s in ("r", "l"):
            x = coords[f"{joint}_{s}"].to_numpy()
            assert np.abs(np.diff(x)).max() < 1.5 * d1, (joint, s)
            assert np.abs(np.diff(x, 2)).max() < 1.5 * d2, (joint, s)


def test_same_seed_same_trial_other_seed_other_trial():
    a = walking_kinematics(10.0, FS, GAIT, np.random.default_rng(5))
    b = walking_kinematics(10.0, FS, GAIT, np.random.default_rng(5))
    c = walking_kinematics(10.0, FS, GAIT, np.random.default_rng(6))
    for x, y in zip(a, b):
        pd.testing.assert_frame_equal(x, y, check_exact=True)
    assert not np.allclose(a[0]["knee_flexion_l"], c[0]["knee_flexion_l"])
    assert not np.allclose(a[1]["time_s"].iloc[:3], c[1]["time_s"].iloc[:3])


# --------------------------------------------------------------------------- OpenSim


def test_feet_on_the_floor_in_opensim():
    from loper_analysis.motion.ik import marker_positions
    from loper_analysis.motion.model import build_lower_body_model

    height = 1.75
    coords, events = walking_kinematics(
        2.0, FS, GAIT, np.random.default_rng(11), leg_length_m=leg_length_from_height(height), start_phase=0.9
    )
    model = build_lower_body_model(height, MASS)
    names = ["RHEE", "RMT1", "RMT5", "LHEE", "LMT1", "LMT5"]
    X = marker_positions(model, {c: coords[c].to_numpy() for c in COORDINATES}, names)
    y = X[:, :, 1]
    heel_above_sole = 0.4 * 0.039 * height  # the model's heel marker sits 0.4 ankle heights above the sole
    sole = np.column_stack([y[:, [0, 3]] - heel_above_sole, y[:, [1, 2, 4, 5]]])
    # the lower foot touches the floor (y = 0) within 2.5 cm all the time
    assert np.abs(sole.min(axis=1)).max() < 0.025
    # right foot: one full stance inside the excerpt; heel down through mid-stance
    t = coords["time_s"].to_numpy()
    ((h, o),) = stances(events, "right")
    l_off = event_times(events, "left", "toe_off")
    l_off = l_off[(l_off > h) & (l_off < o)][0]
    mid = (t >= l_off) & (t <= 0.5 * (l_off + h + 0.5 * (o - h)))  # contralateral toe-off .. half single support
    heel = y[:, 0]
    stance = (t >= h) & (t < o)
    assert mid.sum() > 10
    assert heel[mid].max() - heel[stance].min() < 0.03
    assert heel[stance].min() < heel_above_sole + 0.015
    # and the foot is lifted in swing: the heel rises above 15 cm
    next_hs = event_times(events, "right", "heel_strike")[-1]
    swing = (t > o) & (t < next_hs)
    assert heel[swing].max() > 0.15


# --------------------------------------------------------------------------- input checks


def test_bad_inputs_are_refused():
    rng = np.random.default_rng(0)
    with pytest.raises(LoperInputError, match="timing_cv"):
        walking_kinematics(5.0, FS, GAIT, rng, timing_cv=0.5)
    with pytest.raises(LoperInputError, match="rng"):
        walking_kinematics(5.0, FS, GAIT, 42)
