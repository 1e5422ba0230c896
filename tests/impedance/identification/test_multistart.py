"""The multistart optimiser's bookkeeping: one cost everywhere, the starts-at-best count, the merge rule."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    identify_impedance,
    nuisance_projection,
    starts_at_best,
)
from loper_analysis.impedance.identification.fit import ResidualBatch, multistart_lm
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    perturbed_trial,
    validation_window,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

TRUTH = np.array([60.0, 3.0, 2.0, 0.1, 8.0, 0.3])


@pytest.fixture(scope="module")
def noisy_window():
    """A validation-study window with uniform noise: a minimum well above rounding."""
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    settings = ValidationSettings()
    trial = perturbed_trial(params, TRUTH, settings)
    t, qu, qp, fp, pelvis, _ = trial
    rng = np.random.default_rng(11)
    qu_m = qu + rng.uniform(-0.002, 0.002, qu.shape)
    qp_m = qp + rng.uniform(-0.002, 0.002, qp.shape)
    return validation_window(params, settings, trial, qu_m, qp_m)


def test_starts_at_best_counts_within_a_tenth_of_a_percent_of_the_lowest_start_cost():
    costs = [1.0, 1.0009, 1.0011, 1.9, 0.9999999]
    # threshold 0.9999999 * 1.001 = 1.0009999: 1.0, 1.0009 and the best itself; not 1.0011, and never 1.9
    # (halving one side of the comparison, as once done, would have let every cost up to 2x the best count)
    assert starts_at_best(costs) == 3
    assert starts_at_best([2.0]) == 1
    assert starts_at_best([0.0, 0.0, 1e-20]) == 2  # an exact fit is reached only by the starts at exactly zero
    assert starts_at_best([np.inf, 2.0, 2.001]) == 2  # a start whose simulation diverged never counts


@pytest.mark.parametrize("bad", [[], [1.0, np.nan], [-1.0], [[1.0]], [np.inf, np.inf]])
def test_starts_at_best_refuses_what_is_not_a_list_of_costs(bad):
    with pytest.raises(LoperInputError, match="start costs"):
        starts_at_best(bad)


def test_a_start_on_top_of_a_better_one_merges_and_shares_its_result(noisy_window):
    batch = ResidualBatch(noisy_window, DEFAULT_LOWER, DEFAULT_UPPER)
    a = np.array([100.0, 5.0, 100.0, 5.0, 100.0, 5.0])
    far = np.array([10.0, 9.0, 190.0, 1.0, 20.0, 8.0])
    starts = np.vstack([a, a + 1e-3 * (DEFAULT_UPPER - DEFAULT_LOWER), far])  # the second lies within 0.1 % of a
    P, cost, converged, merged_into = multistart_lm(batch, starts, 60, 1e-6, merge_tol=0.01)
    assert merged_into[0] == merged_into[1]  # both lead to the one that continued
    np.testing.assert_array_equal(P[0], P[1])  # the other shares its end point ...
    assert cost[0] == cost[1] and converged[0] == converged[1]  # ... and its cost, exactly
    assert merged_into[2] == 2  # a start far from both never merges


def test_without_merging_identical_starts_take_identical_paths(noisy_window):
    batch = ResidualBatch(noisy_window, DEFAULT_LOWER, DEFAULT_UPPER)
    start = np.array([100.0, 5.0, 100.0, 5.0, 100.0, 5.0])
    P, cost, _, merged_into = multistart_lm(batch, np.vstack([start, start]), 60, 1e-6, merge_tol=0.0)
    np.testing.assert_array_equal(merged_into, [0, 1])
    np.testing.assert_array_equal(P[0], P[1])
    assert cost[0] == cost[1]


def test_merging_saves_simulations_without_changing_the_best_cost(noisy_window):
    starts = np.random.default_rng(3).uniform(DEFAULT_LOWER, DEFAULT_UPPER, size=(8, 6))
    results = {}
    for tol in (0.0, 0.01):
        batch = ResidualBatch(noisy_window, DEFAULT_LOWER, DEFAULT_UPPER)
        P, cost, _, _ = multistart_lm(batch, starts, 60, 1e-6, merge_tol=tol)
        results[tol] = (cost.min(), batch.n_simulations)
    assert results[0.01][0] == pytest.approx(results[0.0][0], rel=1e-3)
    assert results[0.01][1] <= results[0.0][1]


def test_one_definition_of_cost_in_a_white_fit(noisy_window):
    fit = identify_impedance(noisy_window, n_starts=6, seed=5)
    # the cost is the sum of squared prediction errors here, on the same scale as every start's cost
    assert fit.cost == pytest.approx(fit.sum_sq_error_rad2, rel=1e-12)
    assert fit.cost <= fit.start_costs.min() * (1 + 1e-12)  # the polish never ends above the best start
    assert fit.n_starts == 6 and len(fit.start_costs) == 6
    assert fit.n_starts_at_best == starts_at_best(fit.start_costs)
    assert fit.n_starts_at_best == int(np.sum(fit.start_costs <= fit.start_costs.min() * 1.001))


def test_a_weighted_fit_minimises_the_weighted_cost_and_reports_both(noisy_window):
    first = identify_impedance(noisy_window, n_starts=4, seed=2)
    # a projection that removes two smooth shapes from the residuals: its cost is the weighted one
    m = first.measured.size
    shapes = np.stack([np.sin(np.linspace(0, np.pi, m)), np.linspace(-1, 1, m)])
    errors = np.random.default_rng(0).normal(size=(20, 2)) @ shapes
    weight = nuisance_projection(errors, 2)
    fit = identify_impedance(
        replace(noisy_window, residual_weight=weight), n_starts=4, seed=2, extra_starts=first.estimate
    )
    pe = (fit.measured - fit.model).ravel()
    assert fit.cost == pytest.approx(float(np.sum((weight @ pe) ** 2)), rel=1e-9)
    assert fit.sum_sq_error_rad2 == pytest.approx(float(np.sum(pe**2)), rel=1e-9)
    assert fit.cost < fit.sum_sq_error_rad2  # the projection removes part of every residual vector
    assert fit.n_starts == 5  # the extra start counts
    assert fit.n_starts_at_best == starts_at_best(fit.start_costs)
