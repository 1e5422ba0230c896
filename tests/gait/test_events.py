"""Gait events (hysteresis on the vertical force) and the stride table, against known answers."""

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.events import EVENT_COLUMNS, gait_events
from loper_analysis.gait.strides import STRIDE_COLUMNS, strides_from_events

FS = 1000.0
PEAK_N = 700.0
STANCE_SAMPLES = 720  # half-sine hump from sample s to s + 720
PERIOD_SAMPLES = 1200  # 1.2 s strides
FIRST_HUMP = 300
N_HUMPS = 9
N_SAMPLES = 12_000


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
        f[s : s + STANCE_SAMPLES + 1] = PEAK_N * np.sin(np.pi * j / STANCE_SAMPLES)
    # swing blip above the on-threshold for 30 ms: a 30 ms "stance", shorter than 0.2 s
    f[starts[2] + 900 : starts[2] + 930] = 80.0
    # stance dip below the off-threshold for 20 ms: a 20 ms "swing"
    f[starts[4] + 350 : starts[4] + 370] = 5.0
    # swing bump into the dead band only (40 N): no event by hysteresis
    f[starts[6] + 900 : starts[6] + 1000] = 40.0
    if noise_n:
        f = f + rng.normal(0.0, noise_n, f.size)
    return np.arange(N_SAMPLES) / FS, f, starts


def test_events_fall_on_the_known_crossing_samples_and_blips_are_dropped():
    t, f, starts = _grf()
    rise, fall = _crossings()
    ev = gait_events(t, f, "left", source="S01/T01")
    assert list(ev.columns) == list(EVENT_COLUMNS) == ["side", "event", "time_s", "sample"]
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
    st = strides_from_events(ev, "left")
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
    events = pd.DataFrame(
        {
            "side": "right",
            "event": [
                "toe_off",
                "heel_strike",
                "toe_off",
                "heel_strike",
                "heel_strike",
                "toe_off",
                "toe_off",
                "heel_strike",
                "toe_off",
                "heel_strike",
                "toe_off",
            ],
            "time_s": [0.1, 1.0, 1.6, 2.0, 3.0, 3.5, 3.7, 4.0, 4.6, 5.2, 5.8],
        }
    )
    st = strides_from_events(events, "right")
    # 1.0-2.0 kept; 2.0-3.0 has no toe-off; 3.0-4.0 has two; 4.0-5.2 kept; after 5.2 incomplete
    np.testing.assert_allclose(st["heel_strike_s"], [1.0, 4.0])
    np.testing.assert_allclose(st["toe_off_s"], [1.6, 4.6])
    np.testing.assert_allclose(st["duration_s"], [1.0, 1.2])
    np.testing.assert_allclose(st["stance_s"], [0.6, 0.6], atol=1e-12)
    np.testing.assert_allclose(st["swing_s"], [0.4, 0.6], atol=1e-12)
    np.testing.assert_array_equal(st["stride"], [0, 1])
    assert len(strides_from_events(events, "left")) == 0


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
