"""The stride-to-stride deviation: null-pair errors, the nuisance projection and the refit with null pairs."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    nuisance_projection,
    null_pair_errors,
    prediction_error,
    refit_with_null_pairs,
    simulate_response,
)
from tests.impedance.identification.validation_windows import (
    MID_TRUTH,
    SETTINGS,
    fit,
    mid_trial,
    truth_window,
    window_for,
)

HIP_KNEE = [0, 1, 2, 3]


@pytest.fixture(scope="module")
def trial_mid():
    return mid_trial()


def _deviation_shape(window):
    """A smooth deviation (n_out, 3) that starts at the onset: what a matched stride leaves behind."""
    tau = np.clip(window.time_s - window.onset_s, 0.0, None)
    return np.stack([0.3 * tau**2, -0.5 * tau**2 + 0.2 * tau**3, 0.1 * tau**2], axis=-1)


def _null_pairs(window, t, qu, pu, dq):
    """Null pairs on the window's data grid: perturbed = unperturbed + dq (M, n, 4); pelvis unchanged."""
    M = dq.shape[0]
    return {
        "time_s": t - window.onset_s,
        "q_unperturbed": np.broadcast_to(qu, dq.shape).copy(),
        "q_perturbed": qu + dq,
        "pelvis_angle_unperturbed_rad": np.broadcast_to(pu, (M, len(t))).copy(),
        "pelvis_angle_perturbed_rad": np.broadcast_to(pu, (M, len(t))).copy(),
        "n_pairs": M,
    }


# ---------------------------------------------------------------- projection


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


@pytest.fixture(scope="module")
def projected(trial_mid):
    """Noise-free response plus a smooth deviation whose shape the null pairs show; white and projected fits."""
    window = truth_window(trial_mid)
    shape = _deviation_shape(window)
    biased = replace(window, measured=window.measured + 0.3 * shape)
    rng = np.random.default_rng(5)
    errors = rng.normal(0.0, 0.3, (40, 1)) * shape.reshape(1, -1) + rng.normal(0.0, 1e-5, (40, shape.size))
    weighted = replace(
        biased, residual_weight=nuisance_projection(errors, 1), noise_cov=np.cov(errors, rowvar=False) / 10
    )
    return biased, fit(biased), weighted, fit(weighted)


def test_projecting_out_the_deviation_recovers_the_truth_the_white_fit_misses(projected):
    """White least squares lets the deviation pull D; with the shape projected out
    the fit returns the truth, and the sandwich CI from the null pairs cover it.
    Measured: white D_hip 0.26 (truth 2.0), K_knee 85.6 (75); projected 1.999 and 75.001.
    """
    biased, white, _, result = projected
    truth = MID_TRUTH
    assert abs(white.estimate[1] - truth[1]) > 1.0  # the deviation biases D_hip
    np.testing.assert_allclose(result.estimate[HIP_KNEE], truth[HIP_KNEE], rtol=2e-3)
    assert np.all(result.ci95_low[HIP_KNEE] <= truth[HIP_KNEE]) and np.all(
        truth[HIP_KNEE] <= result.ci95_high[HIP_KNEE]
    )
    # the model (and so the VAF) describe the unweighted prediction error
    np.testing.assert_allclose(result.model, biased.measured - prediction_error(biased, result.estimate), atol=0)


def test_weighted_fit_reports_the_weighted_cost_and_the_unweighted_sum(projected):
    """cost = sum (W PE)^2, the minimised cost; sum_sq_error_rad2 = sum PE^2, which the deviation dominates."""
    _, _, weighted, result = projected
    pe = prediction_error(weighted, result.estimate).ravel()
    np.testing.assert_allclose(result.cost, np.sum((weighted.residual_weight @ pe) ** 2), rtol=1e-10, atol=1e-20)
    np.testing.assert_allclose(result.sum_sq_error_rad2, np.sum(pe**2), rtol=1e-12)
    assert result.sum_sq_error_rad2 > 1e3 * result.cost  # the projection removed the deviation


# ---------------------------------------------------------------- null-pair errors


def test_null_pair_errors_subtract_the_free_response_of_the_initial_state(trial_mid):
    """Three pairs with known errors: identical strides (0); a difference that starts after the
    pre-onset span (its joint-angle difference, as no initial state is seen); a small thigh
    offset before the window (its measured difference minus the change of the model's
    response that offset makes, simulated in full by the peer function simulate_response)."""
    t, qu, _, _, pelvis, _ = trial_mid
    window = window_for(trial_mid)
    theta = MID_TRUTH
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
    still = replace(window, initial_deviation=np.zeros(4), initial_rate=np.zeros(4))
    free = simulate_response(
        replace(still, initial_deviation=np.array([0.0, 1e-4, 0.0, 0.0])), theta
    ) - simulate_response(still, theta)
    measured = np.tile([-1e-4, -1e-4, 0.0], (idx.size, 1))
    # G is linear about theta: 2.6e-9 rad from the full simulation for a 1e-4 rad offset
    np.testing.assert_allclose(errors[2], (measured - free).ravel(), rtol=0, atol=1e-8)
    assert np.abs(free).max() > 1e-5  # the subtraction mattered


# ---------------------------------------------------------------- refit


def _shaped_null_pairs(window, trial, n_pairs, seed):
    """Null pairs whose joint-angle differences are random multiples of _deviation_shape (from the onset on)
    plus 1e-5 rad of independent noise on every coordinate."""
    t, qu, _, _, pelvis, _ = trial
    tau = np.clip(t - window.onset_s, 0.0, None)
    hip, knee, ankle = 0.3 * tau**2, -0.5 * tau**2 + 0.2 * tau**3, 0.1 * tau**2
    # hip = pelvis - q_thigh, knee = q_shank - q_thigh, ankle = q_shank - q_foot (pelvis unchanged)
    per_unit = np.stack([np.zeros_like(tau), -hip, knee - hip, knee - hip - ankle], axis=-1)
    rng = np.random.default_rng(seed)
    dq = rng.normal(0.0, 0.3, (n_pairs, 1, 1)) * per_unit + rng.normal(0.0, 1e-5, (n_pairs,) + qu.shape)
    return _null_pairs(window, t, qu, pelvis, dq)


def test_refit_with_null_pairs_recovers_the_truth(trial_mid, projected):
    biased, white, _, _ = projected
    null = _shaped_null_pairs(biased, trial_mid, 12, seed=9)
    refit = refit_with_null_pairs(
        biased,
        white,
        null,
        n_averaged=10,
        n_components=1,
        min_null_pairs=10,
        n_starts=5,
        seed=0,
        lower=SETTINGS.lower,
        upper=SETTINGS.upper,
    )
    assert (refit.noise_model, refit.n_null_pairs, refit.note) == ("null_pairs", 12, "")
    np.testing.assert_allclose(refit.fit.estimate[HIP_KNEE], MID_TRUTH[HIP_KNEE], rtol=2e-3)


def test_too_few_null_pairs_leave_the_white_fit_standing(trial_mid, projected):
    biased, white, _, _ = projected
    null = _shaped_null_pairs(biased, trial_mid, 4, seed=9)
    refit = refit_with_null_pairs(biased, white, null, n_averaged=10, n_components=1, min_null_pairs=10)
    assert refit.fit is white and refit.noise_model == "white" and refit.n_null_pairs == 4
    assert "4 null pair" in refit.note and "min_null_pairs = 10" in refit.note


def test_refit_rejects_a_mean_of_no_strides(trial_mid, projected):
    biased, white, _, _ = projected
    null = _shaped_null_pairs(biased, trial_mid, 12, seed=9)
    with pytest.raises(LoperInputError, match=r"n_averaged.*got 0"):
        refit_with_null_pairs(biased, white, null, n_averaged=0, n_components=1, min_null_pairs=10)
