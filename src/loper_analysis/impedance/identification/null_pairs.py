"""The stride-to-stride deviation in the identification: null-pair errors, their projection, and the refit.

A mean response's prediction error is not white: the matched unperturbed
stride differs from the perturbed stride's own unperturbed course by a
smooth deviation that the 25 ms pre-onset match cannot remove, and with a
dozen strides its average still biases D. Unperturbed strides paired by the
same rule (*null pairs*, :func:`loper_analysis.impedance.responses.null_pair_windows`)
show that error without a response (:func:`null_pair_errors`). Its few
dominant shapes are projected out of the prediction error
(:func:`nuisance_projection`, ``PreparedWindow.residual_weight``) - the same
as fitting their amplitudes as nuisance parameters - and the CIs come from
the null pairs' covariance by the sandwich ``cov = M C M^T``,
``M = (W J)^+ W``, ``C = PreparedWindow.noise_cov``
(:func:`refit_with_null_pairs`; method: ``docs/null_pairs.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.fit import (
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    ImpedanceFit,
    identify_impedance,
    initial_state_jacobian,
    response_jacobian,
)
from loper_analysis.impedance.identification.intervals import bounded_interval
from loper_analysis.impedance.identification.window import PreparedWindow, initial_state_basis
from loper_analysis.swing_leg.dynamics import joint_angles

__all__ = [
    "NULL_PAIR_COMPONENTS",
    "MIN_NULL_PAIRS",
    "INTERVAL_SCATTERS",
    "check_interval_scatter",
    "NullPairFit",
    "null_pair_errors",
    "nuisance_projection",
    "cross_validated_covariance",
    "refit_with_null_pairs",
]

#: Deviation shapes projected out of the prediction error (``impedance.null_pair_components``).
NULL_PAIR_COMPONENTS: int = 6
#: Fewer null pairs: the white fit stands (``impedance.min_null_pairs``).
MIN_NULL_PAIRS: int = 30
#: Whose scatter gives the refit's 95 % intervals (``impedance.interval_scatter``): the perturbed pairs
#: averaged in the window, the null pairs, or the null pairs each judged by a projection made without it
#: (:func:`refit_with_null_pairs`, :func:`cross_validated_covariance`).
INTERVAL_SCATTERS: tuple[str, ...] = ("perturbed_pairs", "null_pairs", "cross_validated_null_pairs")


def check_interval_scatter(value: str) -> str:
    """``value`` when it is one of :data:`INTERVAL_SCATTERS`, else a LoperInputError naming the config key."""
    if value not in INTERVAL_SCATTERS:
        raise LoperInputError(
            f"impedance.interval_scatter must be one of {', '.join(INTERVAL_SCATTERS)}, got {value!r}"
        )
    return value


@dataclass
class NullPairFit:
    """The fit a row reports: ``noise_model`` ``null_pairs`` (the refit) or ``white`` (the first fit stands).

    ``n_null_pairs`` null pairs were available; ``note`` says why the white fit stands, if it does.
    """

    fit: ImpedanceFit
    noise_model: str
    n_null_pairs: int
    note: str = ""


def null_pair_errors(window: PreparedWindow, impedance, null_pairs: dict) -> np.ndarray:
    """Prediction errors (M, m) of pairs without perturbation, at ``impedance``.

    A null pair (:func:`loper_analysis.impedance.responses.null_pair_windows`) is an
    unperturbed stride matched to another one: its difference is what a
    perturbed-minus-matched difference holds besides the response. Its
    prediction error is ``eps - G s0``: its measured joint-angle difference
    over the window (rad; samples, then hip/knee/ankle, like the fit's
    residuals) minus the model's free response from its own initial state
    ``s0`` (the pre-onset polynomial, as :func:`prepare_window` takes it; ``G``
    the sensitivity to the initial state, linear about ``impedance``).

    ``null_pairs``: ``time_s`` (n,) relative to the onset on the grid of the
    window's data; ``q_perturbed``, ``q_unperturbed`` (M, n, 4);
    ``pelvis_angle_perturbed_rad``, ``pelvis_angle_unperturbed_rad`` (M, n).
    """
    t = np.asarray(null_pairs["time_s"], dtype=float) + window.onset_s
    qp, qu = (np.asarray(null_pairs[k], dtype=float) for k in ("q_perturbed", "q_unperturbed"))
    pp, pu = (
        np.asarray(null_pairs[k], dtype=float) for k in ("pelvis_angle_perturbed_rad", "pelvis_angle_unperturbed_rad")
    )
    n_pairs = qp.shape[0]
    if (
        qp.ndim != 3
        or qp.shape != qu.shape
        or qp.shape[1:] != (t.size, 4)
        or pp.shape != qp.shape[:2]
        or pu.shape != pp.shape
    ):
        raise LoperInputError(
            f"null pairs: q arrays must be (M, {t.size}, 4) and pelvis angles (M, {t.size}); got "
            f"{qp.shape}, {qu.shape}, {pp.shape}, {pu.shape}"
        )
    m = 3 * window.n_samples
    if n_pairs < 1:
        raise LoperInputError("null pairs: none given")
    tol = 1e-6 * window.step_s * window.n_substeps
    idx = np.searchsorted(t, window.time_s - tol)
    if np.any(idx >= t.size) or np.any(np.abs(t[np.minimum(idx, t.size - 1)] - window.time_s) > tol):
        raise LoperInputError(
            f"null pairs: their grid ({t[0]:.4f} .. {t[-1]:.4f} s) does not hold the window's "
            f"samples ({window.time_s[0]:.4f} .. {window.time_s[-1]:.4f} s)"
        )
    sel = (t >= window.onset_s - window.initial_state_span_s - tol) & (t <= window.onset_s + tol)
    V = initial_state_basis(t[sel] - window.time_s[0], window.initial_state_degree)
    dq = qp - qu
    coef, *_ = np.linalg.lstsq(V, np.moveaxis(dq[:, sel], 1, 0).reshape(sel.sum(), -1), rcond=None)
    coef = coef.reshape(V.shape[1], n_pairs, 4)
    s0 = np.concatenate([coef[0], coef[1] if window.initial_state_degree >= 1 else np.zeros((n_pairs, 4))], axis=1)
    eps = np.stack(
        [joint_angles(qp[i, idx], pp[i, idx]) - joint_angles(qu[i, idx], pu[i, idx]) for i in range(n_pairs)]
    ).reshape(n_pairs, m)
    return eps - s0 @ initial_state_jacobian(window, impedance).T


def nuisance_projection(errors, n_components: int) -> np.ndarray:
    """Projection (m, m) that removes the ``n_components`` dominant shapes of ``errors``.

    ``errors`` (M, m): e.g. :func:`null_pair_errors`. The shapes are the
    leading right singular vectors ``V`` of the centred errors; the
    projection is ``I - V V^T``. Used as ``PreparedWindow.residual_weight``
    it fits K and D to what these shapes cannot explain, as if their
    amplitudes were free nuisance parameters.
    """
    E = np.asarray(errors, dtype=float)
    if E.ndim != 2 or not np.all(np.isfinite(E)):
        raise LoperInputError(f"errors must be a finite (M, m) array, got shape {E.shape}")
    r = int(n_components)
    if r != n_components or not 0 <= r < min(E.shape):
        raise LoperInputError(
            f"n_components must be an integer in 0 .. {min(E.shape) - 1} "
            f"(M = {E.shape[0]} null pairs, m = {E.shape[1]}), got {n_components}"
        )
    _, _, vt = np.linalg.svd(E - E.mean(axis=0), full_matrices=False)
    return np.eye(E.shape[1]) - vt[:r].T @ vt[:r]


def cross_validated_covariance(errors, n_components: int, jacobian, n_averaged: int) -> np.ndarray:
    """Covariance (p, p) of the projected fit's estimate, each null pair judged by a projection made without it.

    The projection removes the null pairs' largest shapes, found from the
    same null pairs; their sample covariance then understates the deviation
    left in the remaining directions (those shapes were chosen because the
    sample varies most along them). Here each null pair ``i`` plays the
    perturbed pair's error once: the projection ``W_-i`` and the mean come
    from the other pairs, its effect on the estimate is
    ``d_i = (J^T W_-i J)^+ J^T W_-i (e_i - mean_-i)``, and the covariance is
    ``(N - 1) / N * mean(d_i d_i^T) / n_averaged`` (the factor removes the
    variance of ``mean_-i``). ``errors`` (N, m) from :func:`null_pair_errors`;
    ``jacobian`` (m, p): sensitivity of the unweighted model response to the
    parameters at the estimate.
    """
    E = np.asarray(errors, dtype=float)
    J = np.asarray(jacobian, dtype=float)
    n = E.shape[0]
    if E.ndim != 2 or J.ndim != 2 or J.shape[0] != E.shape[1] or n < int(n_components) + 3 or int(n_averaged) < 1:
        raise LoperInputError(
            f"cross-validated covariance: errors (N, m) with N >= n_components + 3, jacobian (m, p) "
            f"and n_averaged >= 1 expected, got {E.shape}, {J.shape}, {n_components}, {n_averaged}"
        )
    deltas = np.empty((n, J.shape[1]))
    for i in range(n):
        rest = np.delete(E, i, axis=0)
        JW = nuisance_projection(rest, n_components) @ J
        deltas[i] = np.linalg.pinv(JW.T @ JW, rcond=1e-13) @ JW.T @ (E[i] - rest.mean(axis=0))
    return (n - 1) / n * (deltas.T @ deltas) / n / int(n_averaged)


def refit_with_null_pairs(
    window: PreparedWindow,
    first: ImpedanceFit,
    null_pairs: dict,
    n_averaged: int,
    *,
    n_components: int = NULL_PAIR_COMPONENTS,
    min_null_pairs: int = MIN_NULL_PAIRS,
    cross_validated: bool = False,
    perturbed_pairs: dict | None = None,
    **fit_options,
) -> NullPairFit:
    """Fit again with the null pairs' dominant shapes projected out and CIs from their covariance.

    ``first`` is the white-noise fit of ``window``; ``null_pairs`` as for
    :func:`null_pair_errors` (with ``n_pairs``); ``n_averaged`` the number of
    perturbed strides averaged in ``window`` (the null pairs' covariance is
    divided by it). The refit starts from the first estimate and the random
    starts of ``fit_options`` (keyword arguments of :func:`identify_impedance`).
    The intervals' t quantile has ``N - 1`` degrees of freedom, those of the
    sample covariance of the ``N`` null pairs (:mod:`.intervals`).
    ``cross_validated``: the intervals from :func:`cross_validated_covariance`
    instead of the sandwich of the null pairs' covariance.
    ``perturbed_pairs``: the perturbed-minus-matched pairs of ``window``
    one by one (format of ``null_pairs``, ``series["pairs"]`` of
    :func:`loper_analysis.impedance.responses.subject_onset_response`); when given,
    the intervals come from *their* scatter about the mean instead: the
    sandwich of their covariance divided by ``n_averaged``, with
    ``n_averaged - 1`` degrees of freedom. It holds what the null pairs
    cannot show - each stride answers the pulse about its own course - and
    is the t interval of the mean of the per-stride estimates (to first
    order). The null pairs still shape the fit (the projection). Either
    covariance is multiplied by the pairs' ``covariance_scale`` when they hold one
    (the conditional counterfactual's shared prediction error,
    :func:`loper_analysis.impedance.responses.conditional.covariance_scale`). With fewer
    than ``max(min_null_pairs, n_components + 2)`` null pairs the first fit
    stands and ``note`` says so.
    """
    n_null = int(null_pairs["n_pairs"])
    if n_null < max(int(min_null_pairs), int(n_components) + 2):
        note = (
            f"white-noise fit: {n_null} null pair(s), fewer than min_null_pairs = {min_null_pairs}; "
            "the CI ignore the stride-to-stride deviation"
        )
        return NullPairFit(first, "white", n_null, note)
    if int(n_averaged) < 1:
        raise LoperInputError(f"n_averaged must be >= 1 (strides in the mean response), got {n_averaged}")
    errors = null_pair_errors(window, first.estimate, null_pairs)
    weight = nuisance_projection(errors, n_components)
    cov, dof = np.cov(errors, rowvar=False) / n_averaged * float(null_pairs.get("covariance_scale", 1.0)), n_null - 1
    if perturbed_pairs is not None:
        n_pairs = int(perturbed_pairs["n_pairs"])
        if n_pairs != int(n_averaged) or n_pairs < 3:
            raise LoperInputError(
                f"perturbed pairs: {n_pairs} given for a mean of {n_averaged} strides; "
                "the intervals from their scatter need them all, at least 3"
            )
        cov = np.cov(null_pair_errors(window, first.estimate, perturbed_pairs), rowvar=False) / n_averaged
        cov *= float(perturbed_pairs.get("covariance_scale", 1.0))
        dof = n_pairs - 1
    fit = identify_impedance(
        replace(window, noise_cov=cov, residual_weight=weight), extra_starts=first.estimate, ci_dof=dof, **fit_options
    )
    if cross_validated:
        G = response_jacobian(
            window, fit.estimate, fit_options.get("lower", DEFAULT_LOWER), fit_options.get("upper", DEFAULT_UPPER)
        )
        cv = cross_validated_covariance(errors, n_components, G, n_averaged)
        cv *= float(null_pairs.get("covariance_scale", 1.0))
        sd = np.sqrt(np.clip(np.diag(cv), 0, None))
        sd = np.where(np.diag(G.T @ G) > 0, sd, np.inf)
        low, high = bounded_interval(
            fit.estimate, sd, dof, fit_options.get("lower", DEFAULT_LOWER), fit_options.get("upper", DEFAULT_UPPER)
        )
        with np.errstate(divide="ignore", invalid="ignore"):
            fit = replace(fit, ci95_low=low, ci95_high=high, sd=sd, correlation=cv / np.outer(sd, sd))
    return NullPairFit(fit, "null_pairs", n_null)
