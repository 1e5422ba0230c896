"""Impedance identification: recovery of known impedances, CI coverage, input checks, determinism.

The "measured" data come from :func:`loper_analysis.validation.perturbed_trial`
(fine-step RK4 of the same model with a known impedance), prepared the way
:func:`loper_analysis.validation.run_validation_chunk` does it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.constants import JOINTS, PARAMETERS
from loper_analysis.dynamics import segment_parameters_from_anthropometry
from loper_analysis.errors import LoperInputError
from loper_analysis.identification import (
    identify_impedance,
    nuisance_projection,
    null_pair_errors,
    prediction_error,
    prepare_window,
    simulate_response,
    variance_accounted_for,
)
from loper_analysis.validation import ValidationSettings, perturbed_trial, validation_window

PARAMS = segment_parameters_from_anthropometry(1.73, 64.9)
SETTINGS = ValidationSettings()


def window_for(trial, settings=SETTINGS, *, qu_measured=None, qp_measured=None, **overrides):
    """The window run_validation_chunk builds (q_reference = noise-free unperturbed coordinates)."""
    return validation_window(PARAMS, settings, trial, qu_measured, qp_measured, **overrides)


def fit(window, n_starts=5, seed=0, settings=SETTINGS):
    return identify_impedance(
        window,
        n_starts=n_starts,
        seed=seed,
        lower=settings.lower,
        upper=settings.upper,
        tolerance=getattr(settings, "tolerance", 1e-6),
    )


@pytest.fixture(scope="module")
def trial_mid():
    return perturbed_trial(PARAMS, [75.0, 2.0, 75.0, 2.0, 75.0, 2.0], SETTINGS)


# ---------------------------------------------------------------- model response


def test_response_is_exactly_zero_without_perturbation(trial_mid):
    """The deviation dynamics subtract q_ref'': no force, no initial deviation -> e = 0."""
    t, qu, _, _, pelvis = trial_mid
    window = window_for((t, qu, qu, np.zeros((len(t), 2)), pelvis))
    np.testing.assert_allclose(window.measured, 0.0, rtol=0, atol=0)
    P = np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [150.0, 4.0, 150.0, 4.0, 150.0, 4.0]])
    np.testing.assert_allclose(simulate_response(window, P), 0.0, rtol=0, atol=1e-15)


def test_prediction_error_vanishes_at_the_truth_with_the_truth_step(trial_mid):
    """Identification with the truth's own step size reproduces the data (round trip); measured 2.4e-16 rad."""
    impedance = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])
    window = window_for(trial_mid, n_substeps=SETTINGS.truth_substeps)
    assert np.abs(window.measured).max() > 0.05
    np.testing.assert_allclose(prediction_error(window, impedance), 0.0, rtol=0, atol=1e-13)
    # batch and single evaluation agree bitwise
    batch = simulate_response(window, np.stack([impedance, impedance + 1.0]))
    np.testing.assert_array_equal(batch[0], simulate_response(window, impedance))


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
    t, qu, qp, _, _ = trial
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
    truth = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])
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


# ---------------------------------------------------------------- input checks


def _expect(func, *words):
    with pytest.raises(LoperInputError) as info:
        func()
    for w in words:
        assert w in str(info.value), (w, str(info.value))


def test_prepare_window_rejects_bad_input(trial_mid):
    t, qu, qp, fp, pelvis = trial_mid
    kw = dict(force_perturbed_n=fp, pelvis_angle_unperturbed_rad=pelvis, pelvis_angle_perturbed_rad=pelvis)
    onset = SETTINGS.onset_s

    bad = qu.copy()
    bad[7, 2] = np.nan
    _expect(lambda: prepare_window(t, bad, qp, PARAMS, onset, **kw), "q_unperturbed", "row 7", "nan")
    bad = qp.copy()
    bad[11, 0] = np.inf
    _expect(lambda: prepare_window(t, qu, bad, PARAMS, onset, **kw), "q_perturbed", "row 11", "inf")
    _expect(lambda: prepare_window(t, qu[:, :3], qp, PARAMS, onset, **kw), "q_unperturbed", "(55, 3)")
    _expect(lambda: prepare_window(t, qu, qp[:-1], PARAMS, onset, **kw), "q_perturbed", "54", "55")
    t_bad = t.copy()
    t_bad[10] += 0.002
    _expect(lambda: prepare_window(t_bad, qu, qp, PARAMS, onset, **kw), "time_s", "uniform", "sample 9")
    _expect(lambda: prepare_window(t, qu, qp, PARAMS, onset, window_after_s=1.0, **kw), "window", "longer than the data")
    _expect(lambda: prepare_window(t, qu, qp, PARAMS, onset, window_before_s=1.0, **kw), "window", "longer than the data")
    _expect(lambda: prepare_window(t, qu, qp, PARAMS, onset, n_substeps=2.5, **kw), "n_substeps", "2.5")
    _expect(lambda: prepare_window(t, qu, qp, PARAMS, onset, n_substeps=0, **kw), "n_substeps", "0")


def test_identify_impedance_rejects_bad_input(trial_mid):
    window = window_for(trial_mid)
    lower = np.zeros(6)
    upper = np.array(SETTINGS.upper, dtype=float)
    _expect(lambda: identify_impedance(window, n_starts=0), "n_starts", "0")
    _expect(lambda: identify_impedance(window, n_starts=2.5), "n_starts", "2.5")
    high = lower.copy()
    high[2] = 300.0
    _expect(lambda: identify_impedance(window, lower=high, upper=upper), "K_knee", "300", "200")
    _expect(lambda: identify_impedance(window, lower=lower[:5], upper=upper), "lower", "6")
    _expect(lambda: simulate_response(window, [1.0, 2.0, 3.0]), "impedance", "(3,)")
    _expect(lambda: simulate_response(window, [1.0, np.nan, 3.0, 4.0, 5.0, 6.0]), "impedance")


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


def test_response_jacobian_matches_central_differences():
    from loper_analysis.identification import response_jacobian

    params = segment_parameters_from_anthropometry(1.73, 64.9)
    s = ValidationSettings()
    truth = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])
    t, qu, qp, fp, pel = perturbed_trial(params, truth, s)
    w = prepare_window(t, qu, qp, params, s.onset_s, force_perturbed_n=fp,
                       pelvis_angle_unperturbed_rad=pel, pelvis_angle_perturbed_rad=pel)
    J = response_jacobian(w, truth)
    h = np.array([1e-3, 1e-5] * 3)
    for k in range(6):
        dp = np.zeros(6)
        dp[k] = h[k]
        central = (simulate_response(w, truth + dp) - simulate_response(w, truth - dp)).ravel() / (2 * h[k])
        np.testing.assert_allclose(J[:, k], central, rtol=1e-4, atol=1e-6 * np.abs(central).max())


def test_unconverged_fit_says_so(trial_mid):
    window = window_for(trial_mid)
    result = identify_impedance(window, n_starts=2, seed=0, max_iterations=1)
    assert not result.success
    assert "not converged" in result.message
    # the estimate is still the best point seen, inside the bounds, with its cost
    assert np.all(result.estimate >= 0) and np.all(result.estimate <= [200, 10, 200, 10, 200, 10])
    np.testing.assert_allclose(result.cost, np.sum(prediction_error(window, result.estimate) ** 2), rtol=1e-12)


# ---------------------------------------------------------------- stride-to-stride deviation


def _deviation_shape(window):
    """A smooth deviation (n_out, 3) that starts at the onset: what a matched stride leaves behind."""
    tau = np.clip(window.time_s - window.onset_s, 0.0, None)
    return np.stack([0.3 * tau**2, -0.5 * tau**2 + 0.2 * tau**3, 0.1 * tau**2], axis=-1)


def test_nuisance_projection_is_the_orthogonal_complement_of_the_dominant_shapes():
    rng = np.random.default_rng(3)
    v = np.linalg.qr(rng.normal(size=(30, 2)))[0]  # two orthonormal shapes
    errors = rng.normal(size=(50, 2)) * [3.0, 1.0] @ v.T + 1e-9 * rng.normal(size=(50, 30))
    W = nuisance_projection(errors, 2)
    np.testing.assert_allclose(W @ v, 0.0, atol=1e-8)
    np.testing.assert_allclose(W, W.T, atol=1e-12)
    np.testing.assert_allclose(W @ W, W, atol=1e-12)
    assert np.trace(W) == pytest.approx(28.0, abs=1e-9)
    np.testing.assert_allclose(nuisance_projection(errors, 0), np.eye(30), atol=0)
    with pytest.raises(LoperInputError, match="n_components"):
        nuisance_projection(errors, 30)


def test_projecting_out_the_deviation_recovers_the_truth_the_white_fit_misses(trial_mid):
    """Noise-free response plus a smooth deviation whose shape the null pairs show.

    White least squares lets the deviation pull D; with the shape projected out
    the fit returns the truth, and the sandwich CI from the null pairs cover it.
    Measured: white D_hip 0.26 (truth 2.0), K_knee 85.6 (75); projected 1.999 and 75.001.
    """
    truth = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])
    window = window_for(trial_mid, n_substeps=SETTINGS.truth_substeps)
    shape = _deviation_shape(window)
    biased = replace(window, measured=window.measured + 0.3 * shape)
    white = fit(biased)
    assert abs(white.estimate[1] - truth[1]) > 1.0  # the deviation biases D_hip
    rng = np.random.default_rng(5)
    errors = rng.normal(0.0, 0.3, (40, 1)) * shape.reshape(1, -1) + rng.normal(0.0, 1e-5, (40, shape.size))
    projected = replace(biased, residual_weight=nuisance_projection(errors, 1),
                        noise_cov=np.cov(errors, rowvar=False) / 10)
    result = fit(projected)
    hip_knee = [0, 1, 2, 3]
    np.testing.assert_allclose(result.estimate[hip_knee], truth[hip_knee], rtol=2e-3)
    assert np.all(result.ci95_low[hip_knee] <= truth[hip_knee]) and np.all(truth[hip_knee] <= result.ci95_high[hip_knee])
    # the VAF and cost describe the unweighted prediction error
    np.testing.assert_allclose(result.model, biased.measured - prediction_error(biased, result.estimate), atol=0)


def _null_pairs(window, t, qu, pu, dq):
    """Null pairs on the window's data grid: perturbed = unperturbed + dq (M, n, 4); pelvis unchanged."""
    M = dq.shape[0]
    return {"time_s": t - window.onset_s, "q_unperturbed": np.broadcast_to(qu, dq.shape).copy(),
            "q_perturbed": qu + dq, "pelvis_angle_unperturbed_rad": np.broadcast_to(pu, (M, len(t))).copy(),
            "pelvis_angle_perturbed_rad": np.broadcast_to(pu, (M, len(t))).copy()}


def test_null_pair_errors_subtract_the_free_response_of_the_initial_state(trial_mid):
    """Three pairs with known errors: identical strides (0); a difference that starts after the
    pre-onset span (its joint-angle difference, as no initial state is seen); a small thigh
    offset before the window (its measured difference minus the change of the model's
    response that offset makes, simulated in full by the peer function simulate_response)."""
    t, qu, _, _, pelvis = trial_mid
    window = window_for(trial_mid)
    theta = np.array([75.0, 2.0, 75.0, 2.0, 75.0, 2.0])
    dq = np.zeros((3,) + qu.shape)
    after = np.clip(t - window.onset_s, 0.0, None)
    dq[1, :, 2] = 0.2 * after**2  # shank only, from the onset on: invisible to the pre-onset line
    dq[2, :, 1] = 1e-4  # constant thigh offset
    errors = null_pair_errors(window, theta, _null_pairs(window, t, qu, pelvis, dq))
    assert errors.shape == (3, window.measured.size)
    np.testing.assert_allclose(errors[0], 0.0, atol=1e-15)
    idx = np.searchsorted(t, window.time_s - 1e-9)
    expected = np.stack([np.zeros(idx.size), dq[1, idx, 2], dq[1, idx, 2]], axis=-1)  # hip, knee, ankle
    np.testing.assert_allclose(errors[1], expected.ravel(), atol=1e-9)
    still = replace(window, e0=np.zeros(4), ed0=np.zeros(4))
    free = (simulate_response(replace(still, e0=np.array([0.0, 1e-4, 0.0, 0.0])), theta)
            - simulate_response(still, theta))
    measured = np.tile([-1e-4, -1e-4, 0.0], (idx.size, 1))
    # G is linear about theta: 2.6e-9 rad from the full simulation for a 1e-4 rad offset
    np.testing.assert_allclose(errors[2], (measured - free).ravel(), rtol=0, atol=1e-8)
    assert np.abs(free).max() > 1e-5  # the subtraction mattered
