"""The per-sample IQR outlier rule and the too-few-strides warning, against by-hand answers."""

import warnings

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.outliers import (
    MIN_VALID_STRIDES,
    check_enough_strides,
    iqr_outliers,
)


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


def test_names_must_match_the_signals():
    with pytest.raises(LoperInputError, match="S06: names must be 2 distinct names"):
        iqr_outliers(np.zeros((5, 4, 2)), names=["knee"], source="S06")
