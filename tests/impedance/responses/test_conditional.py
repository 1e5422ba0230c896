"""loper_analysis.impedance.responses.conditional: the ridge prediction against least squares and the Gaussian
conditional
mean, its leave-one-out identity, the covariance factor against simulation, and the conditional counterfactual
returning the planted response where no unperturbed stride is a twin (tests.impedance.responses.twin_strides)."""

import numpy as np
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses import ResponseSettings, subject_onset_response
from loper_analysis.impedance.responses.conditional import (
    PENALTY_GRID,
    covariance_scale,
    loo_penalty,
    loo_weights,
    ridge_weights,
)
from tests.impedance.responses.twin_strides import BUMP_AMP, RATE, bump, twin_trial

TINY = 1e-12  # a penalty this small is least squares


#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20261126


def test_ridge_weights_give_the_least_squares_prediction_and_sum_to_one(rng):
    X = rng.normal(size=(40, 5))
    Y = X @ rng.normal(size=(5, 3)) + 0.7 + 0.1 * rng.normal(size=(40, 3))
    x = rng.normal(size=(4, 5))
    A = np.column_stack([np.ones(40), X])
    coef, *_ = np.linalg.lstsq(A, Y, rcond=None)
    w = ridge_weights(x, X, TINY)
    np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(w @ Y, np.column_stack([np.ones(4), x]) @ coef, atol=1e-9)
    # a large penalty shrinks to the candidates' mean
    np.testing.assert_allclose(ridge_weights(x, X, 1e9), 1 / 40, atol=1e-8)


def test_loo_weights_equal_the_fit_without_each_row(rng):
    X = rng.normal(size=(25, 4))
    W = loo_weights(X, TINY)
    np.testing.assert_allclose(np.diag(W), 0.0, atol=1e-12)
    np.testing.assert_allclose(W.sum(axis=1), 1.0, atol=1e-12)
    for i in (0, 7, 24):
        rest = np.delete(np.arange(25), i)
        np.testing.assert_allclose(W[i, rest], ridge_weights(X[i], X[rest], TINY)[0], atol=1e-9)


def test_weights_give_the_gaussian_conditional_mean(rng):
    # x (2) and y (1) jointly Gaussian: E[y | x] = mu_y + S_yx S_xx^-1 (x - mu_x)
    L = np.array([[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [0.5, -0.4, 0.3]])
    mu = np.array([0.2, -0.1, 1.5])
    Z = mu + rng.normal(size=(20000, 3)) @ L.T
    S = L @ L.T
    x = np.array([[0.9, 0.4], [-1.0, 0.3]])
    exact = mu[2] + (x - mu[:2]) @ np.linalg.solve(S[:2, :2], S[:2, 2])
    np.testing.assert_allclose(ridge_weights(x, Z[:, :2], TINY) @ Z[:, 2], exact, atol=0.02)


def test_loo_penalty_keeps_a_signal_and_shrinks_noise(rng):
    X = rng.normal(size=(60, 6))
    signal = X @ rng.normal(size=(6, 2)) + 0.01 * rng.normal(size=(60, 2))
    assert loo_penalty(X, signal) == PENALTY_GRID[0]
    assert loo_penalty(X, rng.normal(size=(60, 2))) >= 1.0


def test_covariance_scale_matches_simulated_pairs(rng):
    n_pairs, n_cand, reps = 8, 30, 20000
    W = rng.dirichlet(np.ones(n_cand) * 0.5, size=n_pairs)  # rows sum to 1, overlapping candidates
    e_p = rng.normal(size=(reps, n_pairs))
    e_c = rng.normal(size=(reps, n_cand))
    d = e_p - e_c @ W.T
    var_mean = d.mean(axis=1).var()
    scatter = d.var(axis=1, ddof=1).mean() / n_pairs
    assert covariance_scale(W) == pytest.approx(var_mean / scatter, rel=0.03)
    # the candidates' leave-one-out errors as the scatter instead
    X = rng.normal(size=(n_cand, 3))
    S = loo_weights(X, 0.1)
    keep = np.ones(n_cand, dtype=bool)
    keep[:3] = False
    null = (e_c - e_c @ S.T)[:, keep]
    scatter_null = null.var(axis=1, ddof=1).mean() / n_pairs
    assert covariance_scale(W, S, keep) == pytest.approx(var_mean / scatter_null, rel=0.03)
    # one candidate of its own per pair (a distinct matched stride): the scatter is right as it is
    assert covariance_scale(np.eye(n_pairs, n_cand)) == pytest.approx(1.0, abs=1e-12)


def test_conditional_counterfactual_returns_the_planted_response_without_twins(rng):
    # no unperturbed stride is a twin of a perturbed one: the matched stride carries its offset difference,
    # the conditional mean predicts each stride's own offset from its pre-onset course
    scale = {4: 1.0, 8: 1.1, 12: 1.3, 16: 0.8}
    trial, _ = twin_trial(rng, twins={}, amplitudes={p: BUMP_AMP * a for p, a in scale.items()})
    grid = window_times_s(0.125, 0.25, RATE)
    planted = bump(grid)[:, None] * BUMP_AMP * np.mean(list(scale.values()))
    errors = {}
    for counterfactual in ("matched_stride", "conditional"):
        settings = ResponseSettings(min_strides=3, counterfactual=counterfactual)
        response, counts, series = subject_onset_response([trial.inputs()], 100, settings)
        measured = response[[f"{j}_rad_mean" for j in JOINTS]].to_numpy()
        errors[counterfactual] = np.abs(measured - planted).max()
    assert int(counts.iloc[-1]["n_kept"]) == 4
    assert errors["matched_stride"] > 5e-3
    assert errors["conditional"] < 1e-5
    # its null pairs: every candidate predicted from the others, without error
    null = series["null_pairs"]
    assert null["n_pairs"] == 26 - 4
    np.testing.assert_allclose(null["q_perturbed"], null["q_unperturbed"], atol=1e-5)
    pairs = counts.attrs["pairs"]
    assert (pairs["matched_stride"] == -1).all() and pairs["rmsd_rad"].max() < 1e-5
    assert series["pairs"]["covariance_scale"] > 1.0


def test_candidates_whose_swing_cannot_hold_the_window_are_left_out(rng):
    # unperturbed strides with 40-frame swings: the window (onset 13 frames after toe-off + 0.25 s = 45 frames)
    # runs into their next stance, as it would for a perturbed stride too short to keep. Left in the pool they
    # would predict a kept stride's continuation from swings unlike it; left out, the planted response returns.
    short = (1, 2, 3, 5, 9, 13, 20)
    scale = {4: 1.0, 8: 1.1, 12: 1.3, 16: 0.8}
    trial, _ = twin_trial(rng, twins={}, amplitudes={p: BUMP_AMP * a for p, a in scale.items()}, short=short)
    grid = window_times_s(0.125, 0.25, RATE)
    planted = bump(grid)[:, None] * BUMP_AMP * np.mean(list(scale.values()))
    settings = ResponseSettings(min_strides=3, counterfactual="conditional")
    response, counts, series = subject_onset_response([trial.inputs()], 100, settings)
    measured = response[[f"{j}_rad_mean" for j in JOINTS]].to_numpy()
    assert int(counts.iloc[-1]["n_kept"]) == 4
    assert np.abs(measured - planted).max() < 1e-5
    assert series["null_pairs"]["n_pairs"] == 26 - 4 - len(short)


def test_unknown_counterfactual_is_refused():
    with pytest.raises(LoperInputError, match="impedance.counterfactual.*'nearest'"):
        ResponseSettings(counterfactual="nearest")
