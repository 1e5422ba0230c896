"""Fitting K and D to one window: recovery of known impedances, CIs, VAF, the Jacobian, bounds, determinism."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.constants import JOINTS, PARAMETERS
from loper_analysis.impedance.identification import (
    identify_impedance,
    prediction_error,
    prepare_window,
    response_jacobian,
    simulate_response,
    variance_accounted_for,
)
from loper_analysis.impedance.identification.validation import perturbed_trial
from tests.impedance.identification.validation_windows import (
    MID_TRUTH,
    PARAMS,
    SETTINGS,
    expect_error,
    fit,
    mid_trial,
    window_for,
)


@pytest.fixture(scope="module")
def trial_mid():
    return mid_trial()


# ---------------------------------------------------------------- recovery


@pytest.mark.parametrize(
    "truth",
    [
        [0.0, 0.0, 150.0, 4.0, 75.0, 2.0],  # hip on the lower bounds
        [75.0, 2.0, 75.0, 2.0, 75.0, 2.0],
        [150.0, 4.0, 0.0, 0.0, 150.0, 4.0],  # knee on the lower bounds
    ],
)
def test_noise_free_recovery(truth):
    """Measured |error| <= 2.7e-4 N m/rad (K) and 5.3e-6 N m s/rad (D) at hip and knee."""
    truth = np.asarray(truth)
    window = window_for(perturbed_trial(PARAMS, truth, SETTINGS))
    result = fit(window, n_starts=5)
    err = result.estimate - truth
    hip_knee_K = [PARAMETERS.index(p) for p in ("K_hip", "K_knee")]
    hip_knee_D = [PARAMETERS.index(p) for p in ("D_hip", "D_knee")]
    np.testing.assert_allclose(err[hip_knee_K], 0.0, rtol=0, atol=0.05)
    np.testing.assert_allclose(err[hip_knee_D], 0.0, rtol=0, atol=0.005)
    assert np.all(result.vaf_pct[[JOINTS.index("hip"), JOINTS.index("knee")]] > 99.99), result.vaf_pct
    assert result.success, result.message
    assert np.all(result.estimate >= 0.0) and np.all(result.estimate <= np.asarray(SETTINGS.upper))
    # the reported model is measured minus residual
    np.testing.assert_allclose(result.model, simulate_response(window, result.estimate), rtol=0, atol=1e-14)


# ---------------------------------------------------------------- uncertainty


def noisy_fits(trial, n_rep, settings=SETTINGS, n_starts=3):
    t, qu, qp, *_ = trial
    a = settings.noise_peak_to_peak / 2
    out = []
    for rep in range(n_rep):
        rng = np.random.default_rng([7, rep])
        window = window_for(
            trial,
            settings,
            qu_measured=qu + rng.uniform(-a, a, qu.shape),
            qp_measured=qp + rng.uniform(-a, a, qp.shape),
        )
        out.append(fit(window, n_starts=n_starts, seed=rep, settings=settings))
    return out


def test_ci95_coverage_of_hip_and_knee(trial_mid):
    """30 noisy repetitions (0.01 p-p uniform): the 95 % CIs, which include the
    initial-state uncertainty, must cover the truth in >= 75 % of fits for
    every hip and knee parameter (and not be absurdly wide: < 4 x the spread).

    Before the initial state entered the covariance, coverage was K_hip 0.90,
    K_knee 0.77, D_hip 0.63, D_knee 0.80.
    """
    truth = MID_TRUTH
    fits = noisy_fits(trial_mid, 30)
    est = np.array([f.estimate for f in fits])
    for name in ("K_hip", "D_hip", "K_knee", "D_knee"):
        i = PARAMETERS.index(name)
        covered = np.array([f.ci95_low[i] <= truth[i] <= f.ci95_high[i] for f in fits])
        assert 0.75 <= covered.mean() <= 1.0, (name, covered.mean())
        half = np.median([(f.ci95_high[i] - f.ci95_low[i]) / 2 for f in fits])
        assert half < 4 * 1.96 * est[:, i].std(), (name, half, est[:, i].std())
    assert all(np.all(f.ci95_low <= f.estimate) and np.all(f.estimate <= f.ci95_high) for f in fits)


def test_correlation_matrix_symmetric_with_unit_diagonal(trial_mid):
    result = noisy_fits(trial_mid, 1)[0]
    C = result.correlation
    assert C.shape == (6, 6)
    np.testing.assert_allclose(C, C.T, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.diag(C), 1.0, rtol=0, atol=1e-12)
    assert np.all(np.abs(C) <= 1.0 + 1e-12)


def test_variance_accounted_for_analytic_cases():
    rng = np.random.default_rng(11)
    y = rng.normal(size=(40, 3))
    np.testing.assert_allclose(variance_accounted_for(y, y), 100.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(variance_accounted_for(y, np.zeros_like(y)), 0.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(variance_accounted_for(y, 0.5 * y), 75.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(variance_accounted_for(y, -y), -300.0, rtol=0, atol=1e-12)
    # a column without signal has no VAF
    y[:, 1] = 0.0
    assert np.isnan(variance_accounted_for(y, y)[1])


def test_white_fit_cost_is_the_sum_of_squared_prediction_errors(trial_mid):
    """Without residual_weight the minimised cost and the unweighted sum are the same number."""
    t, qu, qp, *_ = trial_mid
    rng = np.random.default_rng(1)
    window = window_for(trial_mid, qp_measured=qp + rng.uniform(-0.005, 0.005, qp.shape))
    result = fit(window, n_starts=3)
    sse = np.sum(prediction_error(window, result.estimate) ** 2)
    assert sse > 1e-4  # noise: the cost is not zero
    np.testing.assert_allclose(result.sum_sq_error_rad2, sse, rtol=1e-12)
    np.testing.assert_allclose(result.cost, sse, rtol=1e-12)


# ---------------------------------------------------------------- input checks and bounds


def test_identify_impedance_rejects_bad_input(trial_mid):
    window = window_for(trial_mid)
    lower = np.zeros(6)
    upper = np.array(SETTINGS.upper, dtype=float)
    expect_error(lambda: identify_impedance(window, n_starts=0), "n_starts", "0")
    expect_error(lambda: identify_impedance(window, n_starts=2.5), "n_starts", "2.5")
    high = lower.copy()
    high[2] = 300.0
    expect_error(lambda: identify_impedance(window, lower=high, upper=upper), "K_knee", "300", "200")
    expect_error(lambda: identify_impedance(window, lower=lower[:5], upper=upper), "lower", "6")


# ---------------------------------------------------------------- determinism


def test_same_seed_same_result_bitwise(trial_mid):
    window = window_for(trial_mid)
    a = fit(window, n_starts=4, seed=123)
    b = fit(window, n_starts=4, seed=123)
    for name in ("estimate", "ci95_low", "ci95_high", "starts", "start_estimates", "start_costs", "model"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.cost == b.cost and a.n_simulations == b.n_simulations
    c = fit(window, n_starts=4, seed=124)
    assert not np.array_equal(a.starts, c.starts)
    # the starts are uniform draws inside the bounds
    assert np.all(a.starts >= 0.0) and np.all(a.starts <= np.asarray(SETTINGS.upper))
    # different starts, same optimum (noise-free data)
    np.testing.assert_allclose(c.estimate, a.estimate, rtol=0, atol=1e-3)


# ---------------------------------------------------------------- Jacobian and convergence


def test_response_jacobian_matches_central_differences(trial_mid):
    t, qu, qp, fp, pel, tf = trial_mid
    w = prepare_window(
        t,
        qu,
        qp,
        PARAMS,
        SETTINGS.onset_s,
        force_perturbed_n=fp,
        force_time_s=tf,
        pelvis_angle_unperturbed_rad=pel,
        pelvis_angle_perturbed_rad=pel,
    )
    truth = MID_TRUTH
    J = response_jacobian(w, truth)
    h = np.array([1e-3, 1e-5] * 3)
    for k in range(6):
        dp = np.zeros(6)
        dp[k] = h[k]
        central = (simulate_response(w, truth + dp) - simulate_response(w, truth - dp)).ravel() / (2 * h[k])
        np.testing.assert_allclose(J[:, k], central, rtol=1e-4, atol=1e-6 * np.abs(central).max())


def test_unconverged_fit_says_so(trial_mid):
    """One LM iteration and one polish evaluation: no minimum is reached, and the fit says so."""
    window = window_for(trial_mid)
    result = identify_impedance(window, n_starts=2, seed=0, max_iterations=1, polish_max_evaluations=1)
    assert not result.success
    assert "not converged" in result.message
    # the estimate is still the best point seen, inside the bounds, with its cost
    assert np.all(result.estimate >= 0) and np.all(result.estimate <= [200, 10, 200, 10, 200, 10])
    np.testing.assert_allclose(result.cost, np.sum(prediction_error(window, result.estimate) ** 2), rtol=1e-12)


def test_best_start_polished_to_the_minimum_converges(trial_mid):
    """Multistart cut after 3 iterations, then the polish: the same minimum as the full fit, reported converged."""
    window = window_for(trial_mid)
    full = identify_impedance(window, n_starts=4, seed=0)
    short = identify_impedance(window, n_starts=4, seed=0, max_iterations=3)
    assert full.success and short.success, short.message
    np.testing.assert_allclose(short.estimate, full.estimate, rtol=1e-6, atol=1e-8)


def test_parameter_bounds_are_in_the_order_of_the_parameters():
    from loper_analysis.impedance.identification import parameter_bounds

    lower, upper = parameter_bounds((1.0, 200.0), (0.5, 10.0))
    np.testing.assert_array_equal(lower, [1.0, 0.5, 1.0, 0.5, 1.0, 0.5])
    np.testing.assert_array_equal(upper, [200.0, 10.0, 200.0, 10.0, 200.0, 10.0])
