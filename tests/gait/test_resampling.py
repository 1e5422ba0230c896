"""Resampling onto normalised time (cut, normalise) and onto windows around onsets, against analytic ramps."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import (
    PHASE_BOUNDS,
    cut,
    normalise,
    window,
    window_times_s,
)


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
    assert set(PHASE_BOUNDS) == {"stride", "stance", "swing"}
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


def test_bad_windows_name_the_source():
    ramp = np.arange(100.0)
    tt = np.arange(100) * 0.01
    with pytest.raises(LoperInputError, match=r"S05: window 1 \(0.5 .. 1.2 s\) lies outside the data"):
        cut(tt, ramp, [0.1, 0.5], [0.4, 1.2], source="S05")
    with pytest.raises(LoperInputError, match="S05: window 0 needs finite start < end"):
        cut(tt, ramp, [0.4], [0.4], source="S05")
    with pytest.raises(LoperInputError, match="S05: window .* lies outside the data"):
        window(tt, ramp, [0.01], 0.05, 0.1, 100.0, source="S05")


def test_non_finite_values_only_matter_inside_a_window():
    ramp = np.arange(100.0)
    tt = np.arange(100) * 0.01
    bad = ramp.copy()
    bad[70] = np.nan
    cut(tt, bad, [0.1], [0.6])  # the gap lies outside the window: fine
    with pytest.raises(LoperInputError, match=r"S05: values are not finite at sample 70 .* inside window 1"):
        cut(tt, bad, [0.1, 0.5], [0.6, 0.9], source="S05")
