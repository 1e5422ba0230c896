"""A start whose simulation diverges is a normal event of a multistart fit: handled without a floating-point
warning, whatever the CPU, and never chosen."""

from __future__ import annotations

import warnings

import numpy as np

from loper_analysis.impedance.identification.fit import costs_of, multistart_lm


class ExplodingBatch:
    """Residuals that grow like exp(60 p) in the first parameter (overflowing to inf beyond p = 11.8, their squares
    beyond p = 5.9), with a least-squares minimum at p = (0.5, 1, 2, 3, 4, 5): the batch interface multistart_lm
    uses (``lb``, ``ub``, ``typical``, ``residuals_and_jacobians``), as a negative stiffness makes a swing-leg
    response grow."""

    target = np.array([0.5, 1.0, 2.0, 3.0, 4.0, 5.0])

    def __init__(self):
        self.lb, self.ub = np.zeros(6), np.full(6, 20.0)
        self.typical = 0.01 * (self.ub - self.lb)

    def residuals(self, p: np.ndarray) -> np.ndarray:
        with np.errstate(over="ignore"):  # the simulation's own overflow (numba's RK4 gives inf without a warning)
            grow = np.exp(60.0 * p[:, :1]) - np.exp(30.0)
        return np.concatenate([grow, p[:, 1:] - self.target[1:]], axis=1)

    def residuals_and_jacobians(self, sets: np.ndarray):
        step = 1e-7 * np.maximum(np.abs(sets), self.typical)
        r0 = self.residuals(sets)
        J = np.empty((len(sets), 6, 6))
        for k in range(6):
            shifted = sets.copy()
            shifted[:, k] += step[:, k]
            with np.errstate(over="ignore", invalid="ignore"):
                J[:, :, k] = (self.residuals(shifted) - r0) / step[:, k : k + 1]
        return r0, J


def test_costs_of_diverged_residuals_are_infinite_without_a_warning():
    rows = np.array([[1.0, 2.0], [1e200, 0.0], [np.inf, 1.0], [np.nan, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np.testing.assert_array_equal(costs_of(rows), [5.0, np.inf, np.inf, np.inf])


def test_diverging_starts_are_rejected_and_the_fit_finds_the_minimum_without_a_warning():
    starts = np.array(
        [
            [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],  # converges
            [19.0, 10.0, 10.0, 10.0, 10.0, 10.0],  # inf at once
            [8.0, 3.0, 3.0, 3.0, 3.0, 3.0],  # finite residual, overflowing square
            [5.5, 1.0, 2.0, 3.0, 4.0, 5.0],  # finite cost, steps into overflow
        ]
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        points, costs, converged, merged = multistart_lm(ExplodingBatch(), starts, 200, 1e-12, 0.0)
    best = int(np.argmin(costs))
    np.testing.assert_allclose(points[best], ExplodingBatch.target, atol=1e-6)
    assert costs[1] == np.inf and not converged[1] and (points[1] == starts[1]).all()
    assert costs[2] == np.inf
    assert np.isfinite(costs[0]) and converged[0]
