"""benchmarks/noise_information_limit.py: the information limit of the fit with the noise on the coordinates.

The validation study's noise is on the generalised coordinates of both strides; the fit's prediction error is
a difference of joint angles. The bound must carry that noise through the joint angles: the knee and the
ankle see two coordinates' noise, neighbouring joints share one.
"""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from loper_analysis.impedance.identification import response_jacobian, simulate_deviation
from loper_analysis.swing_leg.dynamics import joint_angles
from tests.impedance.identification.validation_windows import MID_TRUTH, SETTINGS, mid_trial, window_for
from tests.workflow_copy import ROOT

_spec = importlib.util.spec_from_file_location(
    "noise_information_limit", ROOT / "benchmarks" / "noise_information_limit.py"
)
limit = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(limit)

#: SD of the validation study's coordinate noise (uniform, 0.01 peak to peak).
SD = SETTINGS.noise_peak_to_peak / np.sqrt(12)


def test_joint_angle_map_is_the_joint_angles_of_the_model(rng):
    q = rng.normal(size=(50, 4))
    np.testing.assert_allclose(q @ limit.joint_angle_map().T, joint_angles(q, 0.0), rtol=0, atol=1e-15)


def test_knee_and_ankle_carry_two_coordinates_noise_hip_one():
    S = limit.residual_noise_covariance(SD)
    # per stride: hip = -thigh, knee = shank - thigh, ankle = shank - foot; two strides double each entry
    expected = 2 * SD**2 * np.array([[1.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]])
    np.testing.assert_allclose(S, expected, rtol=1e-14)
    assert S[1, 1] == pytest.approx(2 * S[0, 0], rel=1e-14)
    assert S[2, 2] == pytest.approx(2 * S[0, 0], rel=1e-14)


def test_covariance_is_that_of_the_validation_noise(rng):
    # the validation study's draw: uniform +-0.005 on every coordinate of both strides, pelvis angle noise free
    n, a = 200_000, SETTINGS.noise_peak_to_peak / 2
    diff = joint_angles(rng.uniform(-a, a, (n, 4)), 0.0) - joint_angles(rng.uniform(-a, a, (n, 4)), 0.0)
    empirical = np.cov(diff.T)
    # a variance's relative standard error is sqrt((kurtosis - 1) / n) <= sqrt(2 / n) = 0.3 %; a covariance's
    # standard error is below that of the knee variance. 2 % of the knee variance is more than 6 of them.
    S = limit.residual_noise_covariance(SD)
    np.testing.assert_allclose(empirical, S, rtol=0, atol=0.02 * S[1, 1])


def _linear_case(rng, n_samples=20, n_params=3):
    """A linear model of the coordinates' deviation (n, 4, p) and the fit's Jacobian of joint-angle differences
    (n * 3, p)."""
    B = rng.normal(size=(n_samples, 4, n_params))
    J = np.einsum("ac,ncp->nap", limit.joint_angle_map(), B).reshape(-1, n_params)
    return B, J


def test_bound_is_the_propagated_covariance_of_the_weighted_fit(rng):
    B, J = _linear_case(rng)
    n = B.shape[0]
    S = limit.residual_noise_covariance(SD)
    Sigma = np.kron(np.eye(n), S)
    # the weighted least squares as a linear map of the noise of every coordinate of both strides
    M = np.kron(np.eye(n), limit.joint_angle_map())
    E = np.hstack([M, -M])  # perturbed minus unperturbed
    Si = np.linalg.inv(Sigma)
    L = np.linalg.solve(J.T @ Si @ J, J.T @ Si) @ E
    propagated = np.sqrt(np.diag(SD**2 * L @ L.T))
    np.testing.assert_allclose(limit.information_bound(J, S), propagated, rtol=1e-10)
    # the same as white noise of SD sqrt(2) SD on the segment angles' difference (the cart is not in the
    # residual; the joint angles are an invertible map of the three segment angles)
    Ba = B[:, 1:, :].reshape(-1, B.shape[2])
    white = np.sqrt(2) * SD * np.sqrt(np.diag(np.linalg.inv(Ba.T @ Ba)))
    np.testing.assert_allclose(limit.information_bound(J, S), white, rtol=1e-10)
    # the unweighted fit is no better (Gauss-Markov)
    assert np.all(limit.least_squares_sd(J, S) >= limit.information_bound(J, S) * (1 - 1e-12))


def test_weighted_fit_reaches_the_bound_with_uniform_noise(rng):
    B, J = _linear_case(rng)
    n, p = B.shape[0], B.shape[2]
    S = limit.residual_noise_covariance(SD)
    Si = np.linalg.inv(np.kron(np.eye(n), S))
    estimator = np.linalg.solve(J.T @ Si @ J, J.T @ Si)
    draws, a = 4000, SETTINGS.noise_peak_to_peak / 2
    noise_p = rng.uniform(-a, a, (draws, n, 4))
    noise_u = rng.uniform(-a, a, (draws, n, 4))
    residual = (joint_angles(noise_p.reshape(-1, 4), 0.0) - joint_angles(noise_u.reshape(-1, 4), 0.0)).reshape(
        draws, -1
    )
    errors = residual @ estimator.T
    assert errors.shape == (draws, p)
    # the SD of 4000 draws has a relative standard error of about 1/sqrt(2 * 4000) = 1.1 %; 5 % is > 4 of them
    np.testing.assert_allclose(errors.std(axis=0, ddof=1), limit.information_bound(J, S), rtol=0.05)


def test_bound_of_the_fit_equals_white_noise_on_the_simulated_segment_angles():
    # the model's joint-angle response (response_jacobian) against its coordinate deviation (simulate_deviation):
    # the bound from the prediction error with the coordinate noise carried through equals the bound from the
    # segment angles' deviation with white noise of SD sqrt(2) SD
    window = window_for(mid_trial())
    bound = limit.information_bound(response_jacobian(window, MID_TRUTH), limit.residual_noise_covariance(SD))
    h = 1e-4 * np.maximum(np.abs(MID_TRUTH), [2.0, 0.1] * 3)
    sets = np.vstack([MID_TRUTH + np.diag(h), MID_TRUTH - np.diag(h)])
    dev = simulate_deviation(window, sets)[:, :, 1:]  # segment angles only: the cart is not in the residual
    Jq = ((dev[:6] - dev[6:]) / (2 * h[:, None, None])).reshape(6, -1).T
    white = np.sqrt(2) * SD * np.sqrt(np.diag(np.linalg.inv(Jq.T @ Jq)))
    # forward differences (response_jacobian) against central ones: agree to about 1e-6, far inside 1e-4
    np.testing.assert_allclose(bound, white, rtol=1e-4)
