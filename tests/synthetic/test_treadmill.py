"""Split-belt treadmill forces from gait events: shape, swing zeros, body weight, detectable events."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.gait_curves import NominalGait
from loper_analysis.synthetic.treadmill import GRF_COLUMNS, treadmill_grf
from loper_analysis.synthetic.walking import walking_kinematics
from tests.synthetic.gait_events import event_times, stances

FS = 128.0
FS_ANALOG = 1024.0
MASS = 70.0
BW = MASS * 9.81
GAIT = NominalGait()


@pytest.fixture(scope="module")
def grf_trial():
    """A 4-min study trial with its treadmill forces at 1024 Hz (noise 2 N) and without noise."""
    _coords, events = walking_kinematics(240.0, FS, GAIT, np.random.default_rng(7))
    noisy = treadmill_grf(events, 240.0, FS_ANALOG, MASS, rng=np.random.default_rng(8), noise_sd_n=2.0)
    clean = treadmill_grf(events, 240.0, FS_ANALOG, MASS, rng=np.random.default_rng(8), noise_sd_n=0.0)
    return events, noisy, clean


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
    _, noisy, _clean = grf_trial
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
        for h, o in stances(events, side)[:20]:
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
    hs = event_times(events, "right", "heel_strike")
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
            truth = event_times(events, side, kind)
            truth = truth[(truth > 0) & (truth <= t[-1])]
            assert detected.size == truth.size, (side, kind)
            lag = t[detected] - truth
            assert np.all(lag >= 0) and np.all(lag < 1 / FS_ANALOG), (side, kind, lag.min(), lag.max())


def test_grf_partial_stance_at_start():
    _coords, events = walking_kinematics(6.0, FS, GAIT, np.random.default_rng(3), start_phase=0.2)
    f = treadmill_grf(events, 6.0, FS_ANALOG, MASS, noise_sd_n=0.0)
    first = events.groupby("side")["event"].first()
    assert first["right"] == "toe_off"  # right foot in stance at t = 0
    assert f["fz_right_n"].iloc[0] > 100.0


def test_same_seed_same_forces_other_seed_other_noise():
    _, events = walking_kinematics(10.0, FS, GAIT, np.random.default_rng(5))
    ga = treadmill_grf(events, 10.0, FS_ANALOG, MASS, rng=np.random.default_rng(1))
    gb = treadmill_grf(events.copy(), 10.0, FS_ANALOG, MASS, rng=np.random.default_rng(1))
    gc = treadmill_grf(events, 10.0, FS_ANALOG, MASS, rng=np.random.default_rng(2))
    pd.testing.assert_frame_equal(ga, gb, check_exact=True)
    assert not np.allclose(ga["fz_left_n"], gc["fz_left_n"])


def test_bad_inputs_are_refused():
    _, events = walking_kinematics(5.0, FS, GAIT, np.random.default_rng(0))
    with pytest.raises(LoperInputError, match="alternate"):
        treadmill_grf(events[events["event"] != "toe_off"], 5.0, FS_ANALOG, MASS)
    with pytest.raises(LoperInputError, match="side"):
        treadmill_grf(events.assign(side="middle"), 5.0, FS_ANALOG, MASS)
    with pytest.raises(LoperInputError, match="edge_n"):
        treadmill_grf(events, 5.0, FS_ANALOG, 15.0, edge_n=100.0)
