"""The across-subject random-effects mean: analytic cases, weights, and the coverage of its interval."""

from __future__ import annotations

import math

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import t_quantile
from loper_analysis.impedance.identification.group_mean import random_effects_mean


def test_equal_errors_and_a_wide_spread_give_the_t_interval_of_the_estimates():
    theta = np.array([30.0, 45.0, 60.0, 41.0])
    s = np.full(4, 2.0)  # far below the spread (SD 12.3)
    g = random_effects_mean(theta, s)
    half = t_quantile(3) * theta.std(ddof=1) / 2.0
    assert g.mean == pytest.approx(theta.mean(), rel=1e-12)
    assert (g.ci95_low, g.ci95_high) == pytest.approx((theta.mean() - half, theta.mean() + half), rel=1e-12)
    # DerSimonian-Laird with equal errors: tau^2 = sample variance - s^2
    assert g.between_sd == pytest.approx(math.sqrt(theta.var(ddof=1) - 4.0), rel=1e-12)


def test_subjects_that_agree_keep_the_width_of_their_own_errors():
    g = random_effects_mean([50.0, 50.0, 50.0], [6.0, 6.0, 6.0])
    half = t_quantile(2) * 6.0 / math.sqrt(3)
    assert g.mean == pytest.approx(50.0, rel=1e-14) and g.between_sd == 0.0
    assert g.ci95_high - g.mean == pytest.approx(half, rel=1e-12) == g.mean - g.ci95_low


def test_a_fit_without_information_carries_no_weight():
    with_it = random_effects_mean([30.0, 45.0, 60.0, 0.0], [3.0, 5.0, 4.0, math.inf])
    without = random_effects_mean([30.0, 45.0, 60.0], [3.0, 5.0, 4.0])
    assert with_it == without and with_it.n_informative == 3


def test_precise_subjects_weigh_more_when_subjects_do_not_differ():
    g = random_effects_mean([10.0, 20.0], [1.0, 10.0])  # the spread fits the second subject's error: tau = 0
    assert g.between_sd == 0.0
    assert g.mean == pytest.approx((10.0 / 1.0 + 20.0 / 100.0) / (1.0 + 1.0 / 100.0), rel=1e-12)


def test_one_or_no_informative_subject_has_no_interval():
    one = random_effects_mean([42.0, 7.0], [3.0, math.inf])
    assert one.mean == 42.0 and math.isnan(one.ci95_low) and math.isnan(one.ci95_high) and one.n_informative == 1
    none = random_effects_mean([42.0], [math.inf])
    assert math.isnan(none.mean) and none.n_informative == 0


@pytest.mark.parametrize("k", [3, 9])
@pytest.mark.parametrize("tau", [0.0, 5.0, 20.0])
def test_the_interval_holds_the_population_mean_at_least_as_often_as_stated(k, tau):
    """Subjects drawn around a mean of 40 with between-subject SD tau, each estimated with its own error
    (2 to 15): over 2000 studies the interval holds 40 in at least 93 % (binomial SD 0.5 %); with few subjects
    it is conservative by design."""
    rng = np.random.default_rng(1000 * k + int(tau))
    hits = 0
    for _ in range(2000):
        s = rng.uniform(2.0, 15.0, k)
        g = random_effects_mean(40.0 + rng.normal(0.0, tau, k) + rng.normal(0.0, s), s)
        hits += g.ci95_low <= 40.0 <= g.ci95_high
    assert 0.93 <= hits / 2000 <= 1.0


def test_weighting_by_the_fits_errors_narrows_the_interval_and_keeps_its_coverage():
    """Three subjects, one fitted ten times less precisely, no between-subject spread: the t interval of the
    estimates, blind to their errors, is about three times as wide (median 20.0 against 6.1 here); both hold
    the mean in at least 95 % of 4000 studies."""
    rng = np.random.default_rng(7)
    s = np.array([1.0, 1.0, 10.0])
    plain, rand, plain_width, rand_width = 0, 0, [], []
    for _ in range(4000):
        theta = 40.0 + rng.normal(0.0, s)
        half = t_quantile(2) * theta.std(ddof=1) / math.sqrt(3)
        plain += abs(theta.mean() - 40.0) <= half
        plain_width.append(2 * half)
        g = random_effects_mean(theta, s)
        rand += g.ci95_low <= 40.0 <= g.ci95_high
        rand_width.append(g.ci95_high - g.ci95_low)
    assert plain / 4000 >= 0.95 and rand / 4000 >= 0.95
    assert np.median(rand_width) < 0.4 * np.median(plain_width)


def test_bad_input_is_named():
    with pytest.raises(LoperInputError, match="one length"):
        random_effects_mean([1.0, 2.0], [1.0])
    with pytest.raises(LoperInputError, match="finite"):
        random_effects_mean([1.0, math.nan], [1.0, 1.0])
    with pytest.raises(LoperInputError, match=">= 0"):
        random_effects_mean([1.0, 2.0], [1.0, -1.0])
