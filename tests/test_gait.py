"""Gait events, strides, time normalisation and the IQR outlier rule against known answers."""

import math
import warnings

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait import (
    MIN_VALID_STRIDES,
    STRIDE_COLUMNS,
    TooFewStridesWarning,
    check_enough_strides,
    cut,
    gait_events,
    iqr_outliers,
    normalise,
    strides,
    window,
    window_times_s,
)

FS = 1000.0
PEAK_N = 700.0
STANCE_SAMPLES = 720  # half-sine hump from sample s to s + 720
PERIOD_SAMPLES = 1200  # 1.2 s strides
FIRST_HUMP = 300
N_HUMPS = 9
N_SAMPLES = 12_000


@pytest.fixture
def rng():
    return np.random.default_rng(20240611)


def _crossings():
    """Offsets (samples from hump start) of the first sample >= 50 N and the first <= 20 N after the peak."""
    rise = STANCE_SAMPLES / math.pi * math.asin(50.0 / PEAK_N)  # 16.38
    fall = STANCE_SAMPLES - STANCE_SAMPLES / math.pi * math.asin(20.0 / PEAK_N)  # 713.45
    # the crossings are unambiguous: far from a sample boundary
    assert 0.2 < rise % 1 < 0.8 and 0.2 < fall % 1 < 0.8
    return math.ceil(rise), math.ceil(fall)


def _grf(noise_n=0.0, rng=None):
    """Half-sine stance humps plus noise blips; returns time, force, hump starts."""
    f = np.zeros(N_SAMPLES)
    j = np.arange(STANCE_SAMPLES + 1)
    starts = FIRST_HUMP + PERIOD_SAMPLES * np.arange(N_HUMPS)
    for s in starts:
        f[s:s + STANCE_SAMPLES + 1] = PEAK_N * np.sin(np.pi * j / STANCE_SAMPLES)
    # swing blip above the on-threshold for 30 ms: a 30 ms "stance", shorter than 0.2 s
    f[starts[2] + 900:starts[2] + 930] = 80.0
    # stance dip below the off-threshold for 20 ms: a 20 ms "swing"
    f[starts[4] + 350:starts[4] + 370] = 5.0
    # swing bump into the dead band only (40 N): no event by hysteresis
    f[starts[6] + 900:starts[6] + 1000] = 40.0
    if noise_n:
        f = f + rng.normal(0.0, noise_n, f.size)
    return np.arange(N_SAMPLES) / FS, f, starts


def test_events_fall_on_the_known_crossing_samples_and_blips_are_dropped():
    t, f, starts = _grf()
    rise, fall = _crossings()
    ev = gait_events(t, f, "left", source="S01/T01")
    assert list(ev.columns) == ["side", "event", "time_s", "sample"]
    assert (ev["side"] == "left").all()
    hs = ev.loc[ev.event == "heel_strike", "sample"].to_numpy()
    to = ev.loc[ev.event == "toe_off", "sample"].to_numpy()
    np.testing.assert_array_equal(hs, starts + rise)
    np.testing.assert_array_equal(to, starts + fall)
    np.testing.assert_array_equal(ev["event"].to_numpy()[:2], ["heel_strike", "toe_off"])
    np.testing.assert_allclose(ev["time_s"], ev["sample"] / FS, rtol=0, atol=1e-12)
    # the force at the event samples is on the right side of the thresholds, one sample earlier is not
    assert (f[hs] >= 50).all() and (f[hs - 1] < 50).all()
    assert (f[to] <= 20).all() and (f[to - 1] > 20).all()
    dropped = ev.attrs["dropped"]
    assert [d["phase"] for d in dropped] == ["swing", "stance"]  # shortest first: the 20 ms dip
    assert dropped[0]["start_sample"] == starts[4] + 350 and dropped[0]["end_sample"] == starts[4] + 370
    np.testing.assert_allclose(dropped[0]["duration_s"], 0.020, atol=1e-12)
    assert dropped[1]["start_sample"] == starts[2] + 900 and dropped[1]["end_sample"] == starts[2] + 930
    np.testing.assert_allclose(dropped[1]["duration_s"], 0.030, atol=1e-12)


def test_events_with_noise_are_within_one_sample(rng):
    t, f, starts = _grf(noise_n=0.5, rng=rng)
    rise, fall = _crossings()
    ev = gait_events(t, f, "right")
    hs = ev.loc[ev.event == "heel_strike", "sample"].to_numpy()
    to = ev.loc[ev.event == "toe_off", "sample"].to_numpy()
    assert hs.size == N_HUMPS and to.size == N_HUMPS
    assert np.abs(hs - (starts + rise)).max() <= 1
    assert np.abs(to - (starts + fall)).max() <= 1


def test_exact_threshold_values_count_as_crossed():
    f = np.array([0, 10, 30, 49.9, 50.0, 80, 300, 300, 300, 300, 80, 20.1, 20.0, 10, 0, 0, 0, 0, 0, 0, 0, 60, 60])
    t = np.arange(f.size) * 0.1
    ev = gait_events(t, f, "left", min_stance_s=0.0, min_swing_s=0.0)
    np.testing.assert_array_equal(ev["sample"], [4, 12, 21])
    np.testing.assert_array_equal(ev["event"], ["heel_strike", "toe_off", "heel_strike"])


def test_start_inside_stance_or_dead_band():
    # starts loaded: the first event is a toe-off
    f = np.r_[np.full(300, 600.0), np.zeros(500), np.full(400, 600.0), np.zeros(300)]
    t = np.arange(f.size) / FS
    ev = gait_events(t, f, "left")
    np.testing.assert_array_equal(ev["sample"], [300, 800, 1200])
    np.testing.assert_array_equal(ev["event"], ["toe_off", "heel_strike", "toe_off"])
    # starts in the dead band and rises: the state is unknown, the first rise is no heel strike
    f = np.r_[np.full(100, 30.0), np.full(400, 600.0), np.zeros(400), np.full(300, 600.0)]
    ev = gait_events(np.arange(f.size) / FS, f, "left")
    np.testing.assert_array_equal(ev["sample"], [500, 900])


def test_strides_table_durations():
    t, f, starts = _grf()
    rise, fall = _crossings()
    ev = pd.concat([gait_events(t, f, "left"), gait_events(t, 0.5 * f, "right")], ignore_index=True)
    st = strides(ev, "left")
    assert list(st.columns) == list(STRIDE_COLUMNS)
    assert len(st) == N_HUMPS - 1
    np.testing.assert_array_equal(st["stride"], np.arange(N_HUMPS - 1))
    assert (st["side"] == "left").all()
    np.testing.assert_allclose(st["heel_strike_s"], (starts[:-1] + rise) / FS, atol=1e-12)
    np.testing.assert_allclose(st["toe_off_s"], (starts[:-1] + fall) / FS, atol=1e-12)
    np.testing.assert_allclose(st["end_s"], (starts[1:] + rise) / FS, atol=1e-12)
    np.testing.assert_allclose(st["duration_s"], 1.2, atol=1e-12)
    np.testing.assert_allclose(st["stance_s"], (fall - rise) / FS, atol=1e-12)  # 0.697 s
    np.testing.assert_allclose(st["swing_s"], 1.2 - (fall - rise) / FS, atol=1e-12)  # 0.503 s


def test_strides_without_exactly_one_toe_off_are_dropped():
    events = pd.DataFrame({
        "side": "right",
        "event": ["toe_off", "heel_strike", "toe_off", "heel_strike", "heel_strike", "toe_off", "toe_off",
                  "heel_strike", "toe_off", "heel_strike", "toe_off"],
        "time_s": [0.1, 1.0, 1.6, 2.0, 3.0, 3.5, 3.7, 4.0, 4.6, 5.2, 5.8],
    })
    st = strides(events, "right")
    # 1.0-2.0 kept; 2.0-3.0 has no toe-off; 3.0-4.0 has two; 4.0-5.2 kept; after 5.2 incomplete
    np.testing.assert_allclose(st["heel_strike_s"], [1.0, 4.0])
    np.testing.assert_allclose(st["toe_off_s"], [1.6, 4.6])
    np.testing.assert_allclose(st["duration_s"], [1.0, 1.2])
    np.testing.assert_allclose(st["stance_s"], [0.6, 0.6], atol=1e-12)
    np.testing.assert_allclose(st["swing_s"], [0.4, 0.6], atol=1e-12)
    np.testing.assert_array_equal(st["stride"], [0, 1])
    assert len(strides(events, "left")) == 0


def test_cut_of_a_linear_ramp_is_analytic():
    t = np.arange(0, 10, 1 / 128)
    values = np.column_stack([2.0 + 3.0 * t, -0.5 * t])
    starts = np.array([0.0, 1.23456, 4.0001])
    ends = np.array([1.1, 2.5, t[-1]])
    out = cut(t, values, starts, ends, n_points=101)
    assert out.shape == (3, 101, 2)
    grid = starts[:, None] + (ends - starts)[:, None] * np.linspace(0, 1, 101)
    np.testing.assert_allclose(out[:, :, 0], 2.0 + 3.0 * grid, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out[:, :, 1], -0.5 * grid, rtol=0, atol=1e-12)
    one = cut(t, values[:, 0], starts, ends, n_points=11)
    assert one.shape == (3, 11)
    np.testing.assert_allclose(one[1], 2.0 + 3.0 * np.linspace(1.23456, 2.5, 11), rtol=0, atol=1e-12)
    assert cut(t, values, [], [], 5).shape == (0, 5, 2)


def test_normalise_by_phase_uses_the_stride_table():
    t = np.arange(0, 6, 0.001)
    table = pd.DataFrame({"heel_strike_s": [1.0, 2.2], "toe_off_s": [1.7, 2.9], "end_s": [2.2, 3.4]})
    ramp = 10.0 * t
    np.testing.assert_allclose(normalise(t, ramp, table, "stance", 3), [[10, 13.5, 17], [22, 25.5, 29]], atol=1e-9)
    np.testing.assert_allclose(normalise(t, ramp, table, "swing", 3), [[17, 19.5, 22], [29, 31.5, 34]], atol=1e-9)
    np.testing.assert_allclose(normalise(t, ramp, table, "stride", 3), [[10, 16, 22], [22, 28, 34]], atol=1e-9)
    with pytest.raises(LoperInputError, match="phase must be one of"):
        normalise(t, ramp, table, "double_support")


def test_window_on_a_fixed_grid_around_onsets():
    rel = window_times_s(0.025, 0.25, 128.0)
    np.testing.assert_array_equal(rel * 128, np.arange(-3, 33))  # 25 ms = 3.2 samples -> 3; 250 ms = 32
    t = np.arange(0, 20, 0.001)
    values = np.column_stack([1.0 + 4.0 * t, t])
    onsets = np.array([2.0003, 7.5, 12.25])
    out = window(t, values, onsets, 0.025, 0.25, 128.0)
    assert out.shape == (3, 36, 2)
    np.testing.assert_allclose(out[:, :, 0], 1.0 + 4.0 * (onsets[:, None] + rel), rtol=0, atol=1e-11)
    np.testing.assert_allclose(window(t, values[:, 1], onsets, 0.1, 0.1, 100.0)[:, 10], onsets, atol=1e-12)


def test_iqr_outliers_against_a_by_hand_percentile(rng):
    n_strides, n_samples = 20, 100
    x = rng.normal(0.0, 1.0, (n_strides, n_samples, 2))
    x[3, 10:40, 1] += 25.0  # knee of stride 3: 30 % of samples far out -> removed
    x[7, 50:60, 1] -= 25.0  # knee of stride 7: 10 % -> kept
    x[11, 0:22, 0] += 25.0  # hip of stride 11: 22 % -> removed
    table = iqr_outliers(x, names=["hip", "knee"], source="S02")
    assert list(table.columns) == ["stride", "fraction_outlying_hip", "fraction_outlying_knee", "removed", "reason"]
    # by hand, one sample and one signal at a time
    expected = np.zeros((n_strides, 2))
    for j in range(2):
        for s in range(n_samples):
            q1 = np.percentile(x[:, s, j], 25)
            q3 = np.percentile(x[:, s, j], 75)
            iqr = q3 - q1
            for i in range(n_strides):
                v = x[i, s, j]
                expected[i, j] += (v < q1 - 1.5 * iqr) or (v > q3 + 1.5 * iqr)
    expected /= n_samples
    np.testing.assert_allclose(table[["fraction_outlying_hip", "fraction_outlying_knee"]], expected, atol=0)
    assert table.loc[3, "fraction_outlying_knee"] >= 0.30
    assert 0.10 <= table.loc[7, "fraction_outlying_knee"] < 0.2
    np.testing.assert_array_equal(np.flatnonzero(table["removed"]), [3, 11])
    f3 = 100 * table.loc[3, "fraction_outlying_knee"]
    assert table.loc[3, "reason"] == f"knee: {f3:.1f} % of samples outside 1.5·IQR"
    assert table.loc[11, "reason"].startswith("hip: ")
    assert table.loc[7, "reason"] == ""


def test_iqr_outliers_two_dimensional_and_bounds():
    # per sample the strides are 0, 1, 2, 3, 100 -> Q1 = 1, Q3 = 3, upper bound 6: only 100 is out
    x = np.array([[0.0] * 10, [1.0] * 10, [2.0] * 10, [3.0] * 10, [100.0] * 10])
    table = iqr_outliers(x)
    np.testing.assert_array_equal(table["fraction_outlying_signal"], [0, 0, 0, 0, 1])
    np.testing.assert_array_equal(table["removed"], [False, False, False, False, True])
    assert table.loc[4, "reason"] == "signal: 100.0 % of samples outside 1.5·IQR"
    # a value exactly on the bound (Q3 + 1.5 IQR = 6) is not outlying
    x[4] = 6.0
    assert not iqr_outliers(x)["removed"].any()


def test_too_few_strides():
    assert MIN_VALID_STRIDES == 5
    with pytest.raises(LoperInputError, match="S03/T02: the IQR rule needs >= 4 strides, got 3"):
        iqr_outliers(np.zeros((3, 10)), source="S03/T02")
    with pytest.warns(TooFewStridesWarning, match=r"S04 swing: only 4 valid stride\(s\), fewer than the 5"):
        assert check_enough_strides(4, "S04 swing") is False
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert check_enough_strides(5, "S04 swing") is True
    assert issubclass(TooFewStridesWarning, UserWarning)


def test_bad_inputs_name_the_source():
    t, f, _ = _grf()
    g = f.copy()
    g[4321] = np.nan
    with pytest.raises(LoperInputError, match="S01/T03: vertical_force_n is not finite at sample 4321"):
        gait_events(t, g, "left", source="S01/T03")
    with pytest.raises(LoperInputError, match="S01/T03: vertical_force_n has shape"):
        gait_events(t, f[:-1], "left", source="S01/T03")
    with pytest.raises(LoperInputError, match=r"S01/T03: threshold_on_n \(20.0 N\) must exceed threshold_off_n"):
        gait_events(t, f, "left", threshold_on_n=20.0, threshold_off_n=50.0, source="S01/T03")
    with pytest.raises(LoperInputError, match="S01/T03: no gait event"):
        gait_events(t, np.zeros_like(f), "left", source="S01/T03")
    with pytest.raises(LoperInputError, match="S01/T03: side must be one of"):
        gait_events(t, f, "middle", source="S01/T03")
    with pytest.raises(LoperInputError, match="S01/T03: time_s must increase strictly; sample 5"):
        gait_events(np.r_[t[:5], t[:-5]], f, "left", source="S01/T03")
    ramp = np.arange(100.0)
    tt = np.arange(100) * 0.01
    with pytest.raises(LoperInputError, match=r"S05: window 1 \(0.5 .. 1.2 s\) lies outside the data"):
        cut(tt, ramp, [0.1, 0.5], [0.4, 1.2], source="S05")
    with pytest.raises(LoperInputError, match="S05: window 0 needs finite start < end"):
        cut(tt, ramp, [0.4], [0.4], source="S05")
    with pytest.raises(LoperInputError, match="S05: window .* lies outside the data"):
        window(tt, ramp, [0.01], 0.05, 0.1, 100.0, source="S05")
    bad = ramp.copy()
    bad[70] = np.nan
    cut(tt, bad, [0.1], [0.6])  # the gap lies outside the window: fine
    with pytest.raises(LoperInputError, match=r"S05: values are not finite at sample 70 .* inside window 1"):
        cut(tt, bad, [0.1, 0.5], [0.6, 0.9], source="S05")
    with pytest.raises(LoperInputError, match="S06: names must be 2 distinct names"):
        iqr_outliers(np.zeros((5, 4, 2)), names=["knee"], source="S06")
