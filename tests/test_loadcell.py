"""Sync pulses, clock map and the robot log on mocap frames, against known clocks."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.loadcell import (
    ClockMap,
    OUTPUT_COLUMNS,
    clock_map,
    perturbation_onsets,
    pulse_train_at,
    robot_log_on_mocap_frames,
    rising_edges,
    sync_pulse_starts,
    sync_pulse_train,
)

ROBOT_HZ = 1000.0
ANALOG_HZ = 1024.0
FRAME_HZ = 128.0


def mocap_view(starts, offset_s, ppm, robot_t0_s, robot_duration_s, mocap_duration_s, pulse_s=0.01):
    """The robot's sync train as the mocap analog input records it (zero while the robot is not running).

    Robot clock: the log's sample 0 is at ``robot_t0_s``; pulses start at
    ``robot_t0_s + starts``. Mocap clock: analog sample 0 at t = 0;
    ``t_mocap = offset_s + (1 + ppm * 1e-6) * t_robot``.
    """
    scale = 1 + ppm * 1e-6
    t_analog = np.arange(int(round(mocap_duration_s * ANALOG_HZ))) / ANALOG_HZ
    rel = (t_analog - offset_s) / scale - robot_t0_s  # time since the robot log's sample 0
    running = (rel >= 0) & (rel < robot_duration_s)
    return np.where(running, pulse_train_at(rel, starts, pulse_s), 0.0)


# ---------------------------------------------------------------------------
# pulse train and edges


def test_pulse_train_is_seeded_and_random():
    a = sync_pulse_train(60.0, ROBOT_HZ, seed=4)
    b = sync_pulse_train(60.0, ROBOT_HZ, seed=4)
    c = sync_pulse_train(60.0, ROBOT_HZ, seed=5)
    assert a.shape == (60000,)
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    assert set(np.unique(a)) == {0.0, 5.0}
    starts = sync_pulse_starts(60.0, seed=4)
    intervals = np.diff(starts)
    assert starts[0] >= 0.5 and starts[-1] < 60.0
    assert intervals.min() >= 0.5 and intervals.max() < 1.5 and intervals.std() > 0.2
    # each pulse is 10 ms = 10 samples high
    edges = rising_edges(a, ROBOT_HZ)
    assert edges.size == starts.size
    np.testing.assert_allclose(edges, starts, atol=0.5 / ROBOT_HZ + 1e-12)
    # a longer train starts with the same pulses
    np.testing.assert_array_equal(sync_pulse_starts(120.0, seed=4)[: starts.size], starts)


def test_pulse_train_bad_settings():
    with pytest.raises(LoperInputError, match="periodic"):
        sync_pulse_starts(10.0, 1, min_interval_s=1.0, max_interval_s=1.0)
    with pytest.raises(LoperInputError, match="pulse_s"):
        sync_pulse_train(10.0, ROBOT_HZ, 1, pulse_s=0.6)
    with pytest.raises(LoperInputError, match="duration_s"):
        sync_pulse_train(-1.0, ROBOT_HZ, 1)


def test_rising_edges_interpolate_ramps_exactly():
    fs = 100.0
    t = np.arange(1000) / fs
    true = np.array([1.2345, 4.0071, 7.5])
    x = np.zeros_like(t)
    for e in true:  # 0 -> 2 V ramp over 50 ms centred on e, then high for 0.5 s
        x = np.maximum(x, np.clip((t - e) / 0.05 + 0.5, 0, 1) * 2.0 * (t < e + 0.5))
    np.testing.assert_allclose(rising_edges(x, fs), true, atol=1e-12)
    # explicit threshold: 0.5 V is crossed a quarter of the ramp earlier than 1 V
    np.testing.assert_allclose(rising_edges(x, fs, threshold_v=0.5), true - 0.0125, atol=1e-12)


def test_rising_edges_reject_noise_chatter_and_gaps():
    rng = np.random.default_rng(0)
    fs = 1000.0
    starts = np.array([1.0004, 2.5007, 3.1, 4.9])
    x = pulse_train_at(np.arange(6000) / fs, starts, 0.05) + rng.normal(0, 0.15, 6000)
    edges = rising_edges(x, fs)
    assert edges.size == 4
    np.testing.assert_allclose(edges, starts, atol=2e-3)
    # a rise with chatter around the threshold is one edge
    y = np.zeros(200)
    y[100:] = 5.0
    y[[95, 97]] = 2.6  # brief excursions above 2.5 V without reaching the high band
    y[150:] = 0.0
    y[170:] = 5.0
    e = rising_edges(y, fs)
    np.testing.assert_allclose(e, [99.5e-3, 169.5e-3])
    # an edge inside a NaN gap is not reported
    z = pulse_train_at(np.arange(6000) / fs, starts, 0.05)
    z[2495:2510] = np.nan
    np.testing.assert_allclose(rising_edges(z, fs), starts[[0, 2, 3]], atol=0.5e-3)


def test_rising_edges_refusals():
    with pytest.raises(LoperInputError, match="chan A: the sync signal has no finite sample"):
        rising_edges(np.full(100, np.nan), 1000.0, source="chan A")
    with pytest.raises(LoperInputError, match="chan A: the sync signal is flat"):
        rising_edges(np.full(100, 5.0), 1000.0, source="chan A")
    one = np.zeros(100)
    one[50:60] = 5.0
    with pytest.raises(LoperInputError, match="1 rising edge"):
        rising_edges(one, 1000.0)
    with pytest.raises(LoperInputError, match="outside"):
        rising_edges(one, 1000.0, threshold_v=7.0)


# ---------------------------------------------------------------------------
# clock map


@pytest.mark.parametrize(
    "offset_s, ppm, mocap_duration_s, seed",
    [
        (3.217, 150.0, 200.0, 11),  # robot starts 3.217 s after the mocap; mocap ends mid-train
        (-1.5, -80.0, 250.0, 12),  # robot starts 1.5 s before the mocap (mocap starts mid-train); robot ends first
        (-20.0, 150.0, 150.0, 13),  # mocap starts and ends mid-train
    ],
)
def test_clock_map_recovers_offset_and_drift(offset_s, ppm, mocap_duration_s, seed):
    robot_duration_s = 240.0
    starts = sync_pulse_starts(robot_duration_s, seed)
    robot = sync_pulse_train(robot_duration_s, ROBOT_HZ, seed)
    mocap = mocap_view(starts, offset_s, ppm, 0.0, robot_duration_s, mocap_duration_s)
    r, m = rising_edges(robot, ROBOT_HZ), rising_edges(mocap, ANALOG_HZ)
    assert m.size < r.size or m[0] > offset_s + 1  # the records do not hold the same edges
    cm = clock_map(r, m, source="trial-x")
    assert isinstance(cm, ClockMap)
    assert abs(cm.offset_s - offset_s) < 0.2e-3
    assert abs(cm.scale - (1 + ppm * 1e-6)) < 5e-6
    assert abs(cm.drift_ppm - ppm) < 5.0
    assert cm.rms_residual_s < 0.6e-3  # +-0.5 sample quantisation in each record
    assert cm.n_edges >= 100
    np.testing.assert_allclose(cm.to_robot(cm.to_mocap([1.0, 50.0])), [1.0, 50.0], rtol=1e-12)


def test_clock_map_refuses_a_periodic_train_as_ambiguous():
    starts = np.arange(1.0, 240.0, 1.0)
    robot = pulse_train_at(np.arange(240000) / ROBOT_HZ, starts)
    mocap = mocap_view(starts, -20.0, 100.0, 0.0, 240.0, 120.0)
    with pytest.raises(LoperInputError, match=r"trial-p: ambiguous sync match.*periodic"):
        clock_map(rising_edges(robot, ROBOT_HZ), rising_edges(mocap, ANALOG_HZ), source="trial-p")


def test_clock_map_refuses_too_few_edges():
    r = np.array([1.0, 2.2, 2.9, 4.3, 5.1, 6.6, 7.2, 8.9])
    with pytest.raises(LoperInputError, match="trial-f: mocap_edges_s has 3 edge"):
        clock_map(r, r[:3] + 5.0, source="trial-f")
    # four or more edges in each record, but only three in common
    m = np.concatenate([r[5:], [9.8, 10.6, 12.0]]) + 5.0
    with pytest.raises(LoperInputError, match="trial-f: no 4 consecutive sync edges"):
        clock_map(r, m, source="trial-f")
    # exactly four in common is enough
    m4 = np.concatenate([r[4:], [9.8, 10.6, 12.0]]) + 5.0
    cm = clock_map(r, m4, source="trial-f")
    assert cm.n_edges == 4
    assert abs(cm.offset_s - 5.0) < 1e-9 and abs(cm.scale - 1) < 1e-12


def test_clock_map_refuses_a_clock_jump():
    r = sync_pulse_starts(60.0, 3)
    m = 2.0 + r
    m[m.size // 2 :] += 0.02  # 20 ms jump half-way
    with pytest.raises(LoperInputError, match="trial-j: sync edges do not lie on one line"):
        clock_map(r, m, source="trial-j")


# ---------------------------------------------------------------------------
# robot log on mocap frames

FORCE_COMPONENTS = ((8.0, 0.7, 0.3), (5.0, 2.3, 1.1), (3.0, 6.1, 2.0))  # (N, Hz, rad), all < 10 Hz


def force(t):
    return sum(a * np.sin(2 * np.pi * f * t + p) for a, f, p in FORCE_COMPONENTS)


def make_trial(offset_s, ppm, robot_t0_s, seed, robot_duration_s=60.0, mocap_duration_s=70.0):
    n = int(robot_duration_s * ROBOT_HZ)
    t = robot_t0_s + np.arange(n) / ROBOT_HZ
    flag = np.zeros(n, dtype=np.int64)
    onsets = []
    for t_on in (robot_t0_s + 10.0123, robot_t0_s + 23.4567, robot_t0_s + 41.0009):
        k = int(np.ceil((t_on - robot_t0_s) * ROBOT_HZ))
        flag[k : k + 100] = 1  # 100 ms pulse
        onsets.append(t[k])
    log = pd.DataFrame({
        "time_s": t,
        "force_desired_n": 2.0 * np.sin(2 * np.pi * 100.0 * t),  # to be filtered away
        "force_measured_n": force(t),
        "motor_angle_rad": 0.0,
        "motor_velocity_rad_s": 0.0,
        "sync_v": sync_pulse_train(robot_duration_s, ROBOT_HZ, seed),
        "perturbation": flag,
        "safety_state": 0,
    })
    starts = sync_pulse_starts(robot_duration_s, seed)
    sync = mocap_view(starts, offset_s, ppm, robot_t0_s, robot_duration_s, mocap_duration_s)
    frames = np.arange(int(mocap_duration_s * FRAME_HZ)) / FRAME_HZ
    return log, sync, frames, np.array(onsets)


@pytest.mark.parametrize("offset_s, ppm, robot_t0_s", [(3.217, 150.0, 0.0), (-1.5, -80.0, 5.0)])
def test_robot_log_on_mocap_frames_known_signals(offset_s, ppm, robot_t0_s):
    scale = 1 + ppm * 1e-6
    log, sync, frames, onsets_robot = make_trial(offset_s, ppm, robot_t0_s, seed=21)
    out = robot_log_on_mocap_frames(log, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S01/walk")
    assert tuple(out.columns) == OUTPUT_COLUMNS
    np.testing.assert_array_equal(out["time_s"], frames)
    cm = out.attrs["clock_map"]
    assert abs(cm.offset_s - offset_s) < 0.2e-3 and abs(cm.scale - scale) < 10e-6

    # NaN exactly outside the log's span on the mocap clock
    t_first = offset_s + scale * robot_t0_s
    t_last = offset_s + scale * (robot_t0_s + (len(log) - 1) / ROBOT_HZ)
    inside = (frames >= t_first) & (frames <= t_last)
    for col in OUTPUT_COLUMNS[1:]:
        np.testing.assert_array_equal(out[col].notna().to_numpy(), inside)

    # forces: the analytic signal at the mapped times; tolerance = 0.2 ms clock error times the
    # largest slope, plus linear-interpolation and filter-pass-band error (< 0.01 N)
    robot_time = (frames[inside] - offset_s) / scale
    slope = sum(a * 2 * np.pi * f for a, f, _ in FORCE_COMPONENTS)
    tol = slope * 0.2e-3 + 0.01
    np.testing.assert_allclose(out["force_measured_n"][inside], force(robot_time), atol=tol)

    # the 100 Hz component (2 N) is attenuated to < 1 %, away from the filter's start-up transients
    interior = inside & (frames > t_first + 0.25) & (frames < t_last - 0.25)
    assert np.max(np.abs(out["force_desired_n"][interior])) < 0.02

    # flag stays 0/1 and each 100 ms onset lands within one frame of its mapped time
    assert set(np.unique(out["perturbation"][inside])) == {0.0, 1.0}
    onsets = perturbation_onsets(out["time_s"], out["perturbation"])
    expected = offset_s + scale * onsets_robot
    assert onsets.size == 3
    assert np.all(np.abs(onsets - expected) <= 1 / FRAME_HZ)
    widths = np.array([np.sum((frames >= o) & (out["perturbation"] == 1) & (frames < o + 0.2)) for o in onsets])
    assert np.all((widths >= 12) & (widths <= 14))  # 100 ms = 12.8 frames


def test_robot_log_on_mocap_frames_bad_sync():
    log, sync, frames, _ = make_trial(3.217, 150.0, 0.0, seed=22)
    missing = log.assign(sync_v=np.nan)
    with pytest.raises(LoperInputError, match=r"S02/walk: robot log column 'sync_v': .*no finite sample"):
        robot_log_on_mocap_frames(missing, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S02/walk")
    with pytest.raises(LoperInputError, match=r"S02/walk: mocap sync channel: .*flat"):
        robot_log_on_mocap_frames(log, ROBOT_HZ, np.zeros_like(sync), ANALOG_HZ, frames, source="S02/walk")
    flat = log.assign(sync_v=5.0)
    with pytest.raises(LoperInputError, match=r"S02/walk: robot log column 'sync_v': .*flat"):
        robot_log_on_mocap_frames(flat, ROBOT_HZ, sync, ANALOG_HZ, frames, source="S02/walk")
    with pytest.raises(LoperInputError, match="S02/walk: robot log lacks column.*perturbation"):
        robot_log_on_mocap_frames(log.drop(columns="perturbation"), ROBOT_HZ, sync, ANALOG_HZ, frames,
                                  source="S02/walk")
    with pytest.raises(LoperInputError, match="S02/walk: column 'time_s'.*log_rate_hz"):
        robot_log_on_mocap_frames(log, 500.0, sync, ANALOG_HZ, frames, source="S02/walk")


def test_robot_log_on_mocap_frames_tolerates_missing_sync_samples():
    log, sync, frames, _ = make_trial(-1.5, -80.0, 0.0, seed=23)
    v = log["sync_v"].to_numpy().copy()
    v[20000:23000] = np.nan  # 3 s of missing sync samples in the robot log
    out = robot_log_on_mocap_frames(log.assign(sync_v=v), ROBOT_HZ, sync, ANALOG_HZ, frames, source="S03")
    cm = out.attrs["clock_map"]
    assert abs(cm.offset_s + 1.5) < 0.3e-3 and abs(cm.drift_ppm + 80.0) < 10.0


def test_perturbation_onsets():
    t = np.arange(10) * 0.1
    f = np.array([np.nan, 1, 0, 1, 1, 0, 0, 1, np.nan, 1])
    np.testing.assert_allclose(perturbation_onsets(t, f), [0.3, 0.7])
    with pytest.raises(LoperInputError, match="sample 2"):
        perturbation_onsets(t, np.array([0, 1, 2, 0, 0, 0, 0, 0, 0, 0]))
