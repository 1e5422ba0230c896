"""Sampling inside runs of finite frames (responses.sampling): a not-a-knot cubic spline reproduces a cubic exactly
and the frames at their own times, each run of finite frames is splined alone, a span is placed in the run that
holds it (or none), and a window that does not hold its onset is named."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.sampling import SplineSampler, window_span


def _cubic(t, c):
    return c[0] + c[1] * t + c[2] * t**2 + c[3] * t**3


def test_window_span_holds_the_onset():
    assert window_span(-0.025, 0.25) == (-0.025, 0.25)
    assert window_span("0", 0) == (0.0, 0.0)
    with pytest.raises(LoperInputError) as err:
        window_span(0.01, 0.2, "S01 walk02")
    assert str(err.value) == "S01 walk02: the window must hold the onset: start_s <= 0 <= end_s, got 0.01 .. 0.2 s"
    with pytest.raises(LoperInputError, match=r"^the window must hold the onset: .* got -0.1 .. -0.05 s$"):
        window_span(-0.1, -0.05)
    with pytest.raises(LoperInputError, match=r"^S01: end_s must be a finite number, got nan$"):
        window_span(-0.1, float("nan"), "S01")
    with pytest.raises(LoperInputError, match=r"^start_s must be a number, got None$"):
        window_span(None, 0.2)


def test_a_cubic_is_reproduced_between_frames_and_frames_at_their_times(rng):
    """Two channels, two cubics on 100 Hz frames: any time inside gives the cubic to rounding, frame times the
    frames."""
    t = np.arange(0.0, 1.0, 0.01)
    c1, c2 = rng.normal(size=4), rng.normal(size=4)
    values = np.column_stack([_cubic(t, c1), _cubic(t, c2)])
    sampler = SplineSampler(t, values)
    targets = rng.uniform(t[0], t[-1], (5, 7))
    runs = sampler.run(targets.min(axis=1), targets.max(axis=1))
    np.testing.assert_array_equal(runs, np.zeros(5, int))
    got = sampler(targets, runs)
    assert got.shape == (5, 7, 2)
    np.testing.assert_allclose(got[..., 0], _cubic(targets, c1), atol=1e-12)
    np.testing.assert_allclose(got[..., 1], _cubic(targets, c2), atol=1e-12)
    at_frames = sampler(t[None, 10:20], np.zeros(1, int))
    np.testing.assert_array_equal(at_frames[0], values[10:20])


def test_runs_of_finite_frames_are_splined_alone(rng):
    """Frames 0-39 follow one cubic, frame 40 is NaN, 41-79 another, 80 NaN, 81 a lone finite frame, 82-99 NaN:
    two runs (the lone frame is none); each run's samples are its own cubic, a span across the gap is in none."""
    t = np.arange(100) / 100.0
    c1, c2 = rng.normal(size=4), rng.normal(size=4)
    v = np.where(t < 0.405, _cubic(t, c1), _cubic(t, c2))
    v[[40, 80]] = np.nan
    v[82:] = np.nan
    sampler = SplineSampler(t, v)
    np.testing.assert_array_equal(sampler.starts, [0, 41])
    np.testing.assert_array_equal(sampler.stops, [40, 80])
    assert sampler.finite_spans() == "0.0000 .. 0.3900 s, 0.4100 .. 0.7900 s"
    lo = np.array([0.0, 0.1, 0.41, 0.35, 0.80, 0.81, 0.41 - 1e-6])
    hi = np.array([0.39, 0.2, 0.79, 0.45, 0.81, 0.81, 0.5])
    np.testing.assert_array_equal(sampler.run(lo, hi), [0, 0, 1, -1, -1, -1, 1])  # 1e-6 s early: within tolerance
    targets = np.array([[0.05, 0.123, 0.387], [0.415, 0.6, 0.789]])
    got = sampler(targets, np.array([0, 1]))[..., 0]
    np.testing.assert_allclose(got[0], _cubic(targets[0], c1), atol=1e-12)
    np.testing.assert_allclose(got[1], _cubic(targets[1], c2), atol=1e-12)


def test_a_signal_with_a_nan_in_one_channel_has_no_run_there():
    """A frame is finite only when every channel is: a NaN in the second channel splits the first's run."""
    t = np.arange(10) / 10.0
    v = np.column_stack([t, t])
    v[5, 1] = np.nan
    sampler = SplineSampler(t, v)
    assert sampler.finite_spans() == "0.0000 .. 0.4000 s, 0.6000 .. 0.9000 s"
    empty = SplineSampler(t, np.full(10, np.nan))
    assert empty.finite_spans() == "none"
    np.testing.assert_array_equal(empty.run([0.0, 0.2], [0.1, 0.3]), [-1, -1])
