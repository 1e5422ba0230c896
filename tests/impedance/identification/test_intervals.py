"""loper_analysis.impedance.identification.intervals: t quantile, sandwich covariance and bounds, against analytic
answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.stats import binom
from scipy.stats import t as student_t

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import bounded_interval, nuisance_projection, t_quantile
from loper_analysis.impedance.identification.intervals import sandwich_covariance
from loper_analysis.impedance.identification.null_pairs import cross_validated_covariance


def binomial_band(n: int, p: float = 0.95, level: float = 0.999) -> tuple[float, float]:
    """Shares k / n that a true coverage p gives with probability ``level`` (two-sided)."""
    a = (1 - level) / 2
    return binom.ppf(a, n, p) / n, binom.ppf(1 - a, n, p) / n


def test_t_quantile_is_student_s():
    assert t_quantile(1) == pytest.approx(12.706204736174698, rel=1e-12)
    assert t_quantile(102) == pytest.approx(1.9834950, rel=1e-6)
    assert t_quantile(1e12) == pytest.approx(1.959963984540054, rel=1e-9)
    with pytest.raises(LoperInputError, match="degrees of freedom"):
        t_quantile(0)


def test_the_interval_of_a_straight_line_fit_is_the_textbook_one():
    """y = a + b x through (0, 1), (1, 3), (2, 4): b = 1.5, s^2 = 1/6, se(b) = sqrt(s^2 / 2), t_{0.975, 1}."""
    x, y = np.array([0.0, 1.0, 2.0]), np.array([1.0, 3.0, 4.0])
    J = np.column_stack([np.ones(3), x])
    beta, *_ = np.linalg.lstsq(J, y, rcond=None)
    r = y - J @ beta
    s2 = r @ r / (3 - 2)
    cov = sandwich_covariance(J, s2 * np.eye(3))
    low, high = bounded_interval(beta, np.sqrt(np.diag(cov)), 1, [-np.inf, -np.inf], [np.inf, np.inf])
    half = 12.706204736174698 * np.sqrt(1 / 6 / 2)
    np.testing.assert_allclose(beta, [7 / 6, 1.5], rtol=1e-12)
    np.testing.assert_allclose([low[1], high[1]], [1.5 - half, 1.5 + half], rtol=1e-12)


def test_the_sandwich_of_a_projection_removes_the_projected_noise():
    """Noise only along a shape the weight projects out gives no variance; white noise the OLS variance."""
    rng = np.random.default_rng(3)
    J0 = rng.normal(size=(20, 2))
    v = rng.normal(size=20)
    v /= np.linalg.norm(v)
    W = np.eye(20) - np.outer(v, v)
    np.testing.assert_allclose(sandwich_covariance(W @ J0, np.outer(v, v), W), 0, atol=1e-14)
    np.testing.assert_allclose(sandwich_covariance(J0, 0.04 * np.eye(20)), 0.04 * np.linalg.inv(J0.T @ J0), rtol=1e-10)


def test_an_interval_is_cut_at_the_bounds():
    low, high = bounded_interval(
        [0.05, 0.0, 199.0, 3.0], [0.1, 0.1, 5.0, np.inf], 1e12, [0.0, 0.0, 0.0, 0.0], [10.0, 10.0, 200.0, 10.0]
    )
    z = 1.959963984540054
    np.testing.assert_allclose(low, [0.0, 0.0, 199.0 - 5 * z, 0.0], rtol=1e-9)
    np.testing.assert_allclose(high, [0.05 + 0.1 * z, 0.1 * z, 200.0, 10.0], rtol=1e-9)
    with pytest.raises(LoperInputError, match="inside their bounds"):
        bounded_interval([-0.1], [0.1], 10, [0.0], [1.0])
    with pytest.raises(LoperInputError, match="standard deviations"):
        bounded_interval([0.1], [np.nan], 10, [0.0], [1.0])


def test_coverage_with_the_null_pair_degrees_of_freedom():
    """A linear-in-parameters model whose correlated noise covariance is estimated from N = 8 noise-only samples
    (null pairs) and whose data average n = 4 fresh samples: ``a^T e_mean / sqrt(a^T S a / n)`` is exactly
    Student's t with N - 1 degrees of freedom. With t_{N-1} the 95 % interval of the first parameter holds the truth
    in 95 % of 2000
    replications (within the binomial band); the quantile of 102 degrees of freedom covers only
    2 T_7(t_{0.975, 102}) - 1 = 91.2 %."""
    rng = np.random.default_rng(20240)
    m, N, n, reps = 30, 8, 4, 2000
    t = np.linspace(0, 1, m)
    J = np.column_stack([np.sin(3 * t), t**2])
    L = np.linalg.cholesky(0.01 * np.exp(-(np.subtract.outer(t, t) ** 2) / 0.02) + 1e-4 * np.eye(m))
    truth = np.array([0.5, 0.02])
    lower, upper = np.array([-10.0, -10.0]), np.array([10.0, 10.0])
    hits = {N - 1: 0, 102: 0}
    for _ in range(reps):
        null = (L @ rng.normal(size=(m, N))).T
        y = J @ truth + (L @ rng.normal(size=(m, n))).mean(axis=1)
        est, *_ = np.linalg.lstsq(J, y, rcond=None)
        sd = np.sqrt(np.diag(sandwich_covariance(J, np.cov(null, rowvar=False) / n)))
        for dof in hits:
            low, high = bounded_interval(est, sd, dof, lower, upper)
            hits[dof] += bool(low[0] <= truth[0] <= high[0])
    lo, hi = binomial_band(reps)
    assert lo <= hits[N - 1] / reps <= hi
    expected = 2 * student_t.cdf(t_quantile(102), N - 1) - 1
    assert expected == pytest.approx(0.912, abs=1e-3)
    lo, hi = binomial_band(reps, expected)
    assert lo <= hits[102] / reps <= hi


def test_coverage_at_the_lower_bound():
    """D >= 0 with a true D of 0.02 and SD 0.05: the estimate max(0, unbounded) and its interval cut at 0 hold the
    truth whenever the unbounded interval does (and more often): 400 replications within the binomial band of at
    least 95 %, never below the unbounded count."""
    rng = np.random.default_rng(7)
    truth, sd, reps = 0.02, 0.05, 400
    z = rng.normal(truth, sd, reps)
    plain = np.abs(z - truth) <= 1.959963984540054 * sd
    low, high = bounded_interval(np.maximum(z, 0.0), np.full(reps, sd), 1e12, np.zeros(reps), np.full(reps, 10.0))
    bounded = (low <= truth) & (truth <= high)
    assert np.all(low >= 0) and np.all(bounded[plain])
    assert bounded.sum() >= plain.sum()
    lo, _ = binomial_band(reps)
    assert bounded.mean() >= lo


def test_cross_validated_covariance_without_projection_is_the_sandwich():
    """With no shape projected out, the leave-one-out covariance equals M cov(E) M^T / n exactly (algebra:
    e_i - mean_-i = N / (N - 1) (e_i - mean))."""
    rng = np.random.default_rng(11)
    E, J = rng.normal(size=(25, 12)), rng.normal(size=(12, 3))
    np.testing.assert_allclose(
        cross_validated_covariance(E, 0, J, 4), sandwich_covariance(J, np.cov(E, rowvar=False) / 4), rtol=1e-10
    )


def test_cross_validated_covariance_restores_the_coverage_the_projection_takes():
    """Correlated Gaussian deviations (60 samples), N = 40 null pairs, 6 shapes projected out, means of n = 10
    fresh pairs, 400 replications. The sandwich with the null pairs' own covariance covers the first parameter
    in 349 (87 %): the projection removed the directions in which that sample varies most, so the sample
    understates what is left. Judging each null pair by the projection of the others covers it in 379 (95 %),
    inside the binomial band of 95 %."""
    rng = np.random.default_rng(1)
    m, N, n, r, reps = 60, 40, 10, 6, 400
    t = np.linspace(0, 1, m)
    L = np.linalg.cholesky(0.01 * np.exp(-(np.subtract.outer(t, t) ** 2) / 0.01) + 1e-4 * np.eye(m))
    J = np.column_stack([np.sin(3 * t), t**2])
    truth, bounds = np.array([0.5, 0.2]), (np.full(2, -9.0), np.full(2, 9.0))
    hits = np.zeros(2, int)
    for _ in range(reps):
        E = (L @ rng.normal(size=(m, N))).T
        W = nuisance_projection(E, r)
        est = np.linalg.lstsq(W @ J, W @ (J @ truth + (L @ rng.normal(size=(m, n))).mean(axis=1)), rcond=None)[0]
        for k, cov in enumerate(
            (sandwich_covariance(W @ J, np.cov(E, rowvar=False) / n, W), cross_validated_covariance(E, r, J, n))
        ):
            low, high = bounded_interval(est, np.sqrt(np.diag(cov)), N - 1, *bounds)
            hits[k] += bool(low[0] <= truth[0] <= high[0])
    assert hits.tolist() == [349, 379]
    lo, hi = binomial_band(reps)
    assert hits[0] / reps < lo and lo <= hits[1] / reps <= hi
