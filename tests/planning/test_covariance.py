"""The covariance of (K, D) for one perturbed stride: how it scales with the stride count, its t quantile, the
onsets' pooled scatter and the stride counts it is asked for, each against a value worked out by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.stats import t as student_t

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.planning.covariance import StrideCovariance, pool_onsets, stretch_covariances, stride_counts
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

IMPEDANCE = np.array([55.0, 3.5, 3.0, 0.10, 8.0, 0.3])
VARIANCES = np.array([400.0, 0.25, 9.0, 0.01, 16.0, 0.04])  # one stride's variance of each K and D
SPREAD = np.array([800.0, 0.5, 0.0, 0.0, 32.0, 0.0])  # the part falling as 1/N^2


def test_sd_falls_as_one_over_root_n_with_the_spread_as_one_over_n():
    cov = StrideCovariance(np.diag(VARIANCES), IMPEDANCE, None, 40, spread_covariance=np.diag(SPREAD))
    np.testing.assert_allclose(cov.sd, np.sqrt(VARIANCES))
    for n in (1, 4, 16):
        np.testing.assert_allclose(cov.sd_of(n), np.sqrt(VARIANCES / n + SPREAD / n**2))
    np.testing.assert_allclose(cov.sd_of(4), [math.sqrt(150.0), math.sqrt(0.09375), 1.5, 0.05, math.sqrt(6.0), 0.1])
    a, b = cov.variance_terms()
    np.testing.assert_array_equal(a, VARIANCES)
    np.testing.assert_array_equal(b, SPREAD)


def test_half_width_takes_student_t_at_n_minus_one_or_at_the_fixed_dof():
    per_pair = StrideCovariance(np.diag(VARIANCES), IMPEDANCE, None, 40)  # the perturbed pairs' N - 1
    null = StrideCovariance(np.diag(VARIANCES), IMPEDANCE, 39, 40)  # the null pairs' M - 1
    assert per_pair.t95(10) == pytest.approx(2.2621571628, rel=1e-9)  # t(0.975, 9)
    assert null.t95(10) == pytest.approx(2.0226909200, rel=1e-9)  # t(0.975, 39)
    assert per_pair.t95(1) == math.inf  # one stride: no scatter to take an interval from
    np.testing.assert_allclose(per_pair.half_width(10), student_t.ppf(0.975, 9) * np.sqrt(VARIANCES / 10))
    np.testing.assert_allclose(null.half_width(25), student_t.ppf(0.975, 39) * np.sqrt(VARIANCES / 25))


def test_a_negative_rounding_variance_counts_as_zero():
    cov = np.diag([-1e-18, 0.25, 9.0, 0.01, 16.0, 0.04])
    sc = StrideCovariance(cov, IMPEDANCE, None, 40)
    assert sc.sd[0] == 0.0 and sc.sd_of(3)[0] == 0.0


def _perturbed(ratio: np.ndarray, n_pairs: int, null_variances: np.ndarray = VARIANCES) -> StrideCovariance:
    """An onset whose perturbed pairs scatter ``ratio`` times the variance of its null pairs."""
    null = np.diag(null_variances)
    return StrideCovariance(
        np.diag(ratio * null_variances), IMPEDANCE, None, 100, "", n_pairs, "perturbed_pairs", null_covariance=null
    )


def test_pooled_ratio_is_the_mean_of_the_onsets_ratios_weighted_by_their_pairs_minus_one():
    # 11 pairs (weight 10) at ratio 2, 31 pairs (weight 30) at ratio 4: pooled (10 * 2 + 30 * 4) / 40 = 3.5
    stride_covs = {
        50.0: _perturbed(np.full(6, 2.0), 11),
        100.0: _perturbed(np.full(6, 4.0), 31, 2.0 * VARIANCES),
        150.0: StrideCovariance(
            np.diag(VARIANCES), IMPEDANCE, None, 100, "no perturbed pairs of the pilot at this onset", 0,
            null_covariance=np.diag(3.0 * VARIANCES),
        ),
    }  # fmt: skip
    pooled = pool_onsets(stride_covs)
    np.testing.assert_allclose(np.diag(pooled[50.0].covariance), 3.5 * VARIANCES)
    np.testing.assert_allclose(np.diag(pooled[100.0].covariance), 3.5 * 2.0 * VARIANCES)
    np.testing.assert_allclose(np.diag(pooled[150.0].covariance), 3.5 * 3.0 * VARIANCES)  # the null pairs' sandwich
    assert {o: sc.scatter for o, sc in pooled.items()} == dict.fromkeys(stride_covs, "pooled_perturbed_pairs")
    assert pooled[150.0].note == (
        "perturbed/null pairs' variance ratio pooled over onsets 50, 100 ms (42 perturbed pairs)"
    )  # the note that there were no perturbed pairs is gone


def test_pooling_scales_the_off_diagonal_terms_by_both_parameters_ratios():
    null = np.array([[4.0, 1.0], [1.0, 9.0]])
    null6 = np.eye(6)
    null6[:2, :2] = null
    ratio = np.array([4.0, 9.0, 1.0, 1.0, 1.0, 1.0])
    own = [
        StrideCovariance(
            np.diag(ratio * np.diag(null6)), IMPEDANCE, None, 100, "", 5, "perturbed_pairs", null_covariance=null6
        )
        for _ in range(2)
    ]
    pooled = pool_onsets({50.0: own[0], 100.0: own[1]})[50.0].covariance
    # diag(sqrt r) C diag(sqrt r): 4 * 4, 2 * 3 * 1, 9 * 9
    np.testing.assert_allclose(pooled[:2, :2], [[16.0, 6.0], [6.0, 81.0]])


def test_a_single_onset_with_perturbed_pairs_is_left_as_it_is():
    one = {50.0: _perturbed(np.full(6, 2.0), 11), 100.0: StrideCovariance(np.diag(VARIANCES), IMPEDANCE, 39, 40)}
    pooled = pool_onsets(one)
    assert pooled.keys() == one.keys() and all(pooled[o] is one[o] for o in one) and pooled is not one


@pytest.mark.parametrize("given, counts", [(10, [10]), ([5, 10, 20], [5, 10, 20]), (np.array([4.0, 8.0]), [4, 8])])
def test_stride_counts_are_whole_numbers(given, counts):
    assert stride_counts(given, "plan") == counts


@pytest.mark.parametrize("given", [[0], [2.5], ["ten"], [5, -1]])
def test_a_stride_count_that_is_not_a_whole_number_from_one_is_refused(given):
    with pytest.raises(LoperInputError, match=r"^plan: stride count must be a whole number >= 1"):
        stride_counts(given, "plan")
    with pytest.raises(LoperInputError, match=r"^plan: no stride count given$"):
        stride_counts([], "plan")


def test_stretches_are_planned_for_the_conditional_counterfactual_only():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    with pytest.raises(LoperInputError, match=r"conditional counterfactual, not 'matched_stride'$"):
        matched = ResponseSettings(counterfactual="matched_stride")
        stretch_covariances([], 50.0, [10], params, IMPEDANCE, response=matched)
    assert stretch_covariances([], 50.0, [10], params, IMPEDANCE) == {}  # no trial: no stretch of any size
