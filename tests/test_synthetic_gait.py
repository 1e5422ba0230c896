"""Synthetic gait: stride statistics, joint-angle shapes, continuity, treadmill forces and feet on the floor."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.model import COORDINATES
from loper_analysis.synthetic.gait import (
    CURVE_KEYPOINTS_DEG,
    EVENT_COLUMNS,
    GRF_COLUMNS,
    NominalGait,
    fourier_from_keypoints,
    leg_length_from_height,
    pelvis_height_m,
    treadmill_grf,
    walking_kinematics,
)

FS = 128.0
FS_ANALOG = 1024.0
MASS = 70.0
BW = MASS * 9.81
GAIT = NominalGait()
STRIDE = 60.0 / 36.0


@pytest.fixture(scope="module")
def long_trial():
    """10 min at 128 Hz: about 360 strides per leg."""
    return walking_kinematics(600.0, FS, GAIT, np.random.default_rng(20240611), timing_cv=0.03, amplitude_cv=0.05)


@pytest.fixture(scope="module")
def grf_trial():
    """A 4-min study trial with its treadmill forces at 1024 Hz (noise 2 N) and without noise."""
    coords, events = walking_kinematics(240.0, FS, GAIT, np.random.default_rng(7))
    noisy = treadmill_grf(events, 240.0, FS_ANALOG, MASS, np.random.default_rng(8), noise_sd_n=2.0)
    clean = treadmill_grf(events, 240.0, FS_ANALOG, MASS, np.random.default_rng(8), noise_sd_n=0.0)
    return events, noisy, clean


def _times(events, side, event):
    sel = (events["side"] == side) & (events["event"] == event)
    return events.loc[sel, "time_s"].to_numpy()


def _stances(events, side):
    """(heel strike, toe-off) pairs of complete stances."""
    hs, to = _times(events, side, "heel_strike"), _times(events, side, "toe_off")
    return [(h, to[to > h][0]) for h in hs if np.any(to > h)]


# --------------------------------------------------------------------------- curves


def test_default_coefficients_are_the_fit_of_the_documented_keypoints():
    for joint, kp in CURVE_KEYPOINTS_DEG.items():
        phase, deg = np.array(kp).T
        fit = fourier_from_keypoints(phase, np.deg2rad(deg))
        series = GAIT.joint_series(joint)
        # defaults are printed with 6 decimals (rad)
        np.testing.assert_allclose(series.cos, fit.cos, atol=6e-7)
        np.testing.assert_allclose(series.sin, fit.sin, atol=6e-7)
        np.testing.assert_allclose(series.mean, fit.mean, atol=6e-7)
        # and pass through the key points within 0.4 deg (8 harmonics)
        np.testing.assert_allclose(np.rad2deg(series(phase)), deg, atol=0.4)


def test_nominal_curve_landmarks():
    phase = np.linspace(0.0, 1.0, 2001)
    a = {k: np.rad2deg(v) for k, v in GAIT.joint_angles(phase).items()}
    hip, knee, ankle = a["hip_flexion"], a["knee_flexion"], a["ankle_dorsiflexion"]
    assert abs(hip[0] - 25) < 0.5 and abs(hip.min() + 10) < 0.5 and 0.5 < phase[hip.argmin()] < 0.65
    assert abs(knee[0] - 5) < 0.5 and abs(knee.max() - 60) < 0.5 and 0.7 < phase[knee.argmax()] < 0.85
    loading = (phase > 0.05) & (phase < 0.3)
    assert abs(knee[loading].max() - 15) < 0.5
    assert abs(ankle[0]) < 0.5 and abs(ankle.max() - 10) < 0.5 and abs(ankle.min() + 12) < 0.5
    assert 0.65 < phase[ankle.argmin()] < 0.72  # plantarflexion peak just after toe-off


def test_stance_fraction_warp_moves_toe_off_of_the_curves():
    g = NominalGait(stance_fraction=0.6)
    phase = np.linspace(0.0, 1.0, 4001)
    psi = g.curve_phase(phase[:-1])
    assert np.all(np.diff(psi) > 0)
    np.testing.assert_allclose(g.curve_phase([0.0, 0.6]), [0.0, 0.65], atol=1e-12)
    knee = g.joint_angles([0.6])["knee_flexion"]
    np.testing.assert_allclose(knee, GAIT.knee_flexion_rad([0.65]), atol=1e-12)
    # slope continuous across toe-off and across the stride boundary (C1 warp)
    d = np.diff(np.concatenate([psi, [1.0]])) * 4000
    assert np.max(np.abs(np.diff(d))) < 0.01
    # the trial's toe-offs follow, and the knee there is the curves' toe-off value (38 deg)
    coords, events = walking_kinematics(20.0, 1024.0, g, np.random.default_rng(0), timing_cv=0.0, amplitude_cv=0.0)
    hs, to = _times(events, "right", "heel_strike"), _times(events, "right", "toe_off")
    to = to[to > hs[0]][: hs.size - 1]
    np.testing.assert_allclose((to - hs[: to.size]) / STRIDE, 0.6, atol=1e-9)
    knee_at_to = np.interp(to, coords["time_s"], coords["knee_flexion_r"])
    np.testing.assert_allclose(np.rad2deg(knee_at_to), 38.0, atol=0.5)


# --------------------------------------------------------------------------- timing


def test_stride_duration_mean_and_cv(long_trial):
    _, events = long_trial
    hs = _times(events, "right", "heel_strike")
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
    r = _times(events, "right", "heel_strike")
    for side, event, shift, target in (("left", "heel_strike", 0.0, 0.5), ("right", "toe_off", 0.0, 0.65)):
        t = _times(events, side, event)
        k = np.searchsorted(r, t) - 1
        ok = (k >= 0) & (k + 1 < r.size)
        rel = (t[ok] - r[k[ok]]) / (r[k[ok] + 1] - r[k[ok]]) - shift
        # exact on average; the C1 phase interpolation moves single events by < 1.5 % of a stride
        assert abs(rel.mean() - target) < 0.002
        assert np.max(np.abs(rel - target)) < 0.015
    # events alternate per side and lie inside the trial
    for side in ("left", "right"):
        kinds = events.loc[events["side"] == side, "event"].tolist()
        assert all(a != b for a, b in zip(kinds, kinds[1:]))
    assert events["time_s"].between(0, 600).all() and events["time_s"].is_monotonic_increasing
    assert list(events.columns) == list(EVENT_COLUMNS)


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
        hs = _times(events, side, "heel_strike")
        hip = np.rad2deg(coords[f"hip_flexion_{s}"].to_numpy())
        knee = np.rad2deg(coords[f"knee_flexion_{s}"].to_numpy())
        ankle = np.rad2deg(coords[f"ankle_dorsiflexion_{s}"].to_numpy())
        hip_range, knee_peak, ankle_min, ankle_max = [], [], [], []
        for a, b in zip(hs[:-1], hs[1:]):
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
    ga = treadmill_grf(a[1], 10.0, FS_ANALOG, MASS, np.random.default_rng(1))
    gb = treadmill_grf(b[1], 10.0, FS_ANALOG, MASS, np.random.default_rng(1))
    gc = treadmill_grf(a[1], 10.0, FS_ANALOG, MASS, np.random.default_rng(2))
    pd.testing.assert_frame_equal(ga, gb, check_exact=True)
    assert not np.allclose(ga["fz_left_n"], gc["fz_left_n"])


# --------------------------------------------------------------------------- forces


def _stance_mask(events, side, t):
    mask = np.zeros(t.size, bool)
    kinds = events.loc[events["side"] == side, ["event", "time_s"]].to_numpy()
    start = 0.0 if kinds[0][0] == "toe_off" else None  # in stance at the start
    for kind, tt in kinds:
        if kind == "heel_strike":
            start = tt
        elif start is not None:
            mask |= (t >= start) & (t < tt)
            start = None
    if start is not None:
        mask |= t >= start
    return mask


def test_grf_columns_and_shape(grf_trial):
    _, noisy, clean = grf_trial
    assert list(noisy.columns) == list(GRF_COLUMNS)
    assert len(noisy) == 240 * 1024
    t = noisy["time_s"].to_numpy()
    np.testing.assert_allclose(np.diff(t), 1 / FS_ANALOG, rtol=1e-9)


def test_grf_zero_in_swing_above_threshold_in_stance(grf_trial):
    events, noisy, clean = grf_trial
    t = clean["time_s"].to_numpy()
    for side in ("left", "right"):
        stance = _stance_mask(events, side, t)
        fz = clean[f"fz_{side}_n"].to_numpy()
        assert np.all(fz[~stance] == 0.0) and np.all(clean[f"fx_{side}_n"].to_numpy()[~stance] == 0.0)
        assert fz[stance].min() >= 100.0 - 1e-9  # the edge step, well above a 50 N threshold
        noise = noisy[f"fz_{side}_n"].to_numpy()[~stance]
        assert abs(noise.std() - 2.0) < 0.05 and np.abs(noise).max() < 15.0
        assert np.all(np.isnan(clean[f"cop_x_{side}_m"].to_numpy()[~stance]))


def test_grf_double_hump_and_fore_aft_force(grf_trial):
    events, _, clean = grf_trial
    t = clean["time_s"].to_numpy()
    for side in ("left", "right"):
        fz = clean[f"fz_{side}_n"].to_numpy()
        fx = clean[f"fx_{side}_n"].to_numpy()
        cop = clean[f"cop_x_{side}_m"].to_numpy()
        for h, o in _stances(events, side)[:20]:
            sel = (t >= h) & (t < o)
            u = (t[sel] - h) / (o - h)
            z = fz[sel] / BW
            first, second, mid = z[u < 0.4].max(), z[u > 0.6].max(), z[np.abs(u - 0.5) < 0.01].mean()
            assert 1.05 < first < 1.15 and 1.05 < second < 1.15 and 0.72 < mid < 0.85
            x = fx[sel]
            assert x[u < 0.5].mean() < -0.05 * BW and x[u > 0.5].mean() > 0.05 * BW  # braking, then propulsion
            assert abs(x.sum() / FS_ANALOG) < 0.5  # N·s: no net impulse
            assert cop[sel][0] > cop[sel][-1]  # the belt carries the foot backward


def test_belts_average_body_weight(grf_trial):
    events, noisy, _ = grf_trial
    hs = _times(events, "right", "heel_strike")
    t = noisy["time_s"].to_numpy()
    sel = (t >= hs[0]) & (t < hs[-1])  # whole strides
    total = noisy["fz_left_n"].to_numpy()[sel] + noisy["fz_right_n"].to_numpy()[sel]
    np.testing.assert_allclose(total.mean(), BW, rtol=0.05)
    np.testing.assert_allclose(total.mean(), BW, rtol=0.01)  # in fact


def test_threshold_detector_finds_every_event_within_one_sample(grf_trial):
    events, noisy, _ = grf_trial
    t = noisy["time_s"].to_numpy()
    on, off = 50.0, 30.0  # 50 N threshold, 20 N hysteresis
    for side in ("left", "right"):
        fz = noisy[f"fz_{side}_n"].to_numpy()
        rise = np.flatnonzero((fz[1:] >= on) & (fz[:-1] < on)) + 1
        fall = np.flatnonzero((fz[1:] < off) & (fz[:-1] >= off)) + 1
        for detected, kind in ((rise, "heel_strike"), (fall, "toe_off")):
            truth = _times(events, side, kind)
            truth = truth[(truth > 0) & (truth <= t[-1])]
            assert detected.size == truth.size, (side, kind)
            lag = t[detected] - truth
            assert np.all(lag >= 0) and np.all(lag < 1 / FS_ANALOG), (side, kind, lag.min(), lag.max())


def test_grf_partial_stance_at_start():
    coords, events = walking_kinematics(6.0, FS, GAIT, np.random.default_rng(3), start_phase=0.2)
    f = treadmill_grf(events, 6.0, FS_ANALOG, MASS, noise_sd_n=0.0)
    first = events.groupby("side")["event"].first()
    assert first["right"] == "toe_off"  # right foot in stance at t = 0
    assert f["fz_right_n"].iloc[0] > 100.0


# --------------------------------------------------------------------------- OpenSim


def test_feet_on_the_floor_in_opensim():
    from loper_analysis.kinematics import marker_positions
    from loper_analysis.model import build_lower_body_model

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
    (h, o), = _stances(events, "right")
    l_off = _times(events, "left", "toe_off")
    l_off = l_off[(l_off > h) & (l_off < o)][0]
    mid = (t >= l_off) & (t <= 0.5 * (l_off + h + 0.5 * (o - h)))  # contralateral toe-off .. half single support
    heel = y[:, 0]
    stance = (t >= h) & (t < o)
    assert mid.sum() > 10
    assert heel[mid].max() - heel[stance].min() < 0.03
    assert heel[stance].min() < heel_above_sole + 0.015
    # and the foot is lifted in swing: the heel rises above 15 cm
    next_hs = _times(events, "right", "heel_strike")[-1]
    swing = (t > o) & (t < next_hs)
    assert heel[swing].max() > 0.15


# --------------------------------------------------------------------------- input checks


def test_bad_inputs_are_refused():
    rng = np.random.default_rng(0)
    with pytest.raises(LoperInputError, match="timing_cv"):
        walking_kinematics(5.0, FS, GAIT, rng, timing_cv=0.5)
    with pytest.raises(LoperInputError, match="rng"):
        walking_kinematics(5.0, FS, GAIT, 42)
    with pytest.raises(LoperInputError, match="stance_fraction"):
        NominalGait(stance_fraction=0.4)
    _, events = walking_kinematics(5.0, FS, GAIT, rng)
    with pytest.raises(LoperInputError, match="alternate"):
        treadmill_grf(events[events["event"] != "toe_off"], 5.0, FS_ANALOG, MASS)
    with pytest.raises(LoperInputError, match="side"):
        treadmill_grf(events.assign(side="middle"), 5.0, FS_ANALOG, MASS)
    with pytest.raises(LoperInputError, match="edge_n"):
        treadmill_grf(events, 5.0, FS_ANALOG, 15.0, edge_n=100.0)
