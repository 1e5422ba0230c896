"""loper_analysis.device.clock_sync: rising edges of sync pulses and the robot -> mocap clock map, against known
clocks."""

import numpy as np
import pytest

from loper_analysis.device.clock_sync import (
    MIN_LEVEL_SEPARATION,
    MIN_MATCHED_EDGES,
    ClockMap,
    clock_map,
    require_pulse_train,
    rising_edges,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.sync import (
    pulse_train_at,
    sync_pulse_starts,
)
from tests.sync_records import ANALOG_HZ, ROBOT_HZ, mocap_view

# ---------------------------------------------------------------------------
# edges


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
    robot = pulse_train_at(np.arange(int(round(robot_duration_s * ROBOT_HZ))) / ROBOT_HZ, starts)
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
    assert MIN_MATCHED_EDGES == 4
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
# a pulse train at all


def _mocap_train(seed: int, noise_v: float = 0.0) -> np.ndarray:
    """60 s of the robot's sync train as the mocap analog input records it (5 V, 10 ms pulses), plus noise."""
    starts = sync_pulse_starts(60.0, seed)
    x = mocap_view(starts, 1.3, 80.0, 0.0, 60.0, 60.0)
    return x + np.random.default_rng(seed).normal(0.0, noise_v, x.size)


@pytest.mark.parametrize("noise_v", [0.0, 0.01, 0.1, 0.3])
def test_a_sync_train_passes_as_a_pulse_train(noise_v):
    """The train at 1 % duty, noiseless or with up to 0.3 V of noise on its 5 V swing (a separation of ~17)."""
    got = require_pulse_train(_mocap_train(5, noise_v), ANALOG_HZ, source="trial-t")
    assert got["separation"] >= MIN_LEVEL_SEPARATION
    assert abs(got["low_v"]) < 0.05 and abs(got["high_v"] - 5.0) < 0.1
    assert got["middle_fraction"] < 0.01
    n_edges = rising_edges(_mocap_train(5, noise_v), ANALOG_HZ).size
    assert got["crossings"] == 2 * n_edges  # up and down, once per edge


def _replaced_by(kind: str, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / ANALOG_HZ
    return {
        "gaussian": lambda: rng.normal(2.5, 1.0, n),
        "uniform": lambda: rng.uniform(0.0, 5.0, n),
        "mains": lambda: 0.3 * np.sin(2 * np.pi * 50.0 * t) + rng.normal(0.0, 0.01, n),
    }[kind]()


@pytest.mark.parametrize("kind", ["gaussian", "uniform", "mains"])
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_sync_channel_of_noise_is_no_pulse_train(kind, seed):
    """The sync record with its channel replaced by seeded noise (or mains hum): without the check its random
    edges reached the matching and were blamed on different trains; now the channel is named as holding noise."""
    x = _replaced_by(kind, _mocap_train(seed).size, seed)
    with pytest.raises(LoperInputError) as info:
        require_pulse_train(x, ANALOG_HZ, source="trial-n.c3d: mocap sync channel 'sync'")
    message = str(info.value)
    assert message.startswith("trial-n.c3d: mocap sync channel 'sync': no pulse train: ")
    for words in ("crossings of the halfway level", "in 60 s", "levels not two-valued", "a pulse train at least 8"):
        assert words in message
    assert "the channel holds noise. An unplugged sync cable, or the wrong channel?" in message
    separation = float(message.split("lie only ")[1].split(" ")[0])
    assert separation < 4.5  # noise 2 to 3, a sine 3.9: far below 8
    crossings = int(message.split("no pulse train: ")[1].split(" ")[0])
    assert crossings > 1000


def test_noise_edges_alone_were_blamed_on_different_trains():
    """What the check replaces: noise has edges enough for the matching, which then blames the trains."""
    robot = pulse_train_at(np.arange(60000) / ROBOT_HZ, sync_pulse_starts(60.0, 4))
    noise = _replaced_by("gaussian", 61440, 4)
    edges = rising_edges(noise, ANALOG_HZ)
    assert edges.size > 100
    with pytest.raises(LoperInputError, match="different trains"):
        clock_map(rising_edges(robot, ROBOT_HZ), edges, source="trial-n")


def test_signals_without_two_values_are_left_to_rising_edges():
    """Empty, all-NaN and flat signals: rising_edges names them (see test_rising_edges_refusals)."""
    for x in (np.array([]), np.full(100, np.nan), np.full(100, 5.0)):
        assert require_pulse_train(x, ANALOG_HZ) == {}
    gappy = _mocap_train(6)
    gappy[1000:1500] = np.nan
    assert require_pulse_train(gappy, ANALOG_HZ)["separation"] >= MIN_LEVEL_SEPARATION
