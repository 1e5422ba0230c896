"""The perturbed strides' own scatter of a fit's estimate: a linearised jackknife over the averaged pairs.

The 95 % intervals of a fit with the null-pair noise model come from the scatter of the *null* pairs
(unperturbed strides paired as if perturbed, :mod:`.null_pairs`): they show the counterfactual's error, not how
each perturbed stride answers the pulse about its own course, nor anything else the perturbed strides share that
the unperturbed ones do not. The perturbed pairs themselves show all of it. Leaving pair ``p`` out of the mean
moves the estimate by ``-A (e_p - e_mean) / (n - 1)`` to first order, ``e_p`` (m,) the pair's prediction error
at the estimate (its measured joint-angle difference less the model's response about its own course, with its
own force and initial state: :func:`~loper_analysis.impedance.identification.pair_averaging.pair_windows`) and
``A = (J^T W^T W J)^+ J^T W^T W`` the fit's linear map (``J`` the model response's Jacobian, ``W`` the null
pairs' nuisance projection, both at the estimate); the jackknife variance of the estimate is then

    var_jk = sum_p (A (e_p - e_mean))_i^2 / (n (n - 1)),

times the pairs' ``covariance_scale`` when they carry one (the conditional counterfactual's error shared by all
pairs, which their scatter cannot show; :func:`loper_analysis.impedance.responses.conditional.covariance_scale`).
When the perturbed pairs scatter like the null pairs, ``var_jk / sd^2`` (``sd`` the interval's SD) follows an F
distribution with ``n - 1`` and ``N - 1`` degrees of freedom; a ratio beyond its quantile
:data:`~loper_analysis.impedance.identification.PAIR_SCATTER_LEVEL` says the interval misses part of this fit's
error (:func:`~loper_analysis.impedance.identification.joint_status`, rule 8; ``docs/identification.md``, "Fit
status").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.fit import DEFAULT_LOWER, DEFAULT_UPPER, response_jacobian
from loper_analysis.impedance.identification.null_pairs import nuisance_projection, null_pair_errors
from loper_analysis.impedance.identification.pair_averaging import pair_windows
from loper_analysis.impedance.identification.window import PreparedWindow, simulate_response
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = ["jackknife_sd", "onset_jackknife"]


def jackknife_sd(
    window: PreparedWindow,
    estimate,
    pair_windows: Sequence[PreparedWindow],
    null_pairs: dict | None = None,
    n_components: int = 0,
    *,
    covariance_scale: float = 1.0,
    lower=DEFAULT_LOWER,
    upper=DEFAULT_UPPER,
) -> tuple[np.ndarray, int]:
    """The linearised jackknife SD of each estimate over the averaged perturbed pairs, and its degrees of freedom.

    Parameters
    ----------
    window : PreparedWindow
        The window of the mean response the fit was made on (its model response gives ``J``).
    estimate : (p,) array_like
        The fit's estimate in the order of the window's parameters (p = 6 without couplings: K and D per joint,
        :data:`~loper_analysis.constants.PARAMETERS`; N·m/rad, N·m·s/rad).
    pair_windows : sequence of PreparedWindow
        Each averaged pair as a window of its own (:func:`~loper_analysis.impedance.identification.pair_windows`),
        at least 3.
    null_pairs : dict, optional
        The fit's null pairs (:func:`~loper_analysis.impedance.identification.null_pair_errors`); with
        ``n_components`` > 0 their leading shapes are projected out (``W``) as the fit projects them.
        None: ``W`` is the identity (a white fit).
    n_components : int
        Shapes projected out (``impedance.null_pair_components``).
    covariance_scale : float
        Factor on the variance (> 0): the pairs' ``covariance_scale`` when they carry one.
    lower, upper : array_like
        The fit's bounds, as :func:`~loper_analysis.impedance.identification.response_jacobian` takes them.

    Returns
    -------
    (numpy.ndarray, int)
        SD (p,) in N·m/rad and N·m·s/rad (inf where the response does not depend on the parameter) and the
        degrees of freedom ``n - 1`` of its variance.
    """
    est = np.asarray(estimate, dtype=float)
    n = len(pair_windows)
    if n < 3:
        raise LoperInputError(f"jackknife over the perturbed pairs: at least 3 pairs needed, got {n}")
    if not covariance_scale > 0:
        raise LoperInputError(f"covariance_scale must be > 0, got {covariance_scale}")
    m = 3 * window.n_samples
    E = np.stack([(w.measured - simulate_response(w, est)).ravel() for w in pair_windows])
    if E.shape != (n, m):
        raise LoperInputError(f"pair windows must have the window's {window.n_samples} samples, got errors {E.shape}")
    J = response_jacobian(window, est, lower, upper)
    W = np.eye(m)
    if null_pairs is not None and int(n_components) > 0:
        W = nuisance_projection(null_pair_errors(window, est, null_pairs), int(n_components))
    WJ = W @ J
    A = np.linalg.pinv(WJ.T @ WJ, rcond=1e-13) @ WJ.T @ W
    moves = (E - E.mean(axis=0)) @ A.T
    var = np.sum(moves**2, axis=0) / (n * (n - 1)) * float(covariance_scale)
    sd = np.where(np.sum(WJ**2, axis=0) > 0, np.sqrt(var), np.inf)
    return sd, n - 1


def onset_jackknife(
    window: PreparedWindow,
    estimate,
    pairs: Mapping,
    null_pairs: dict,
    params: SegmentParameters,
    window_options: Mapping,
    settings,
) -> tuple[np.ndarray, int]:
    """:func:`jackknife_sd` of one onset's fit as :func:`~loper_analysis.impedance.identification.impedance.fit_onset`
    makes it.

    ``pairs``: the responses' per-pair series (``series["pairs"]`` of
    :func:`loper_analysis.impedance.responses.subject_onset_response`, with its ``covariance_scale`` when it has
    one), each prepared as a window (:func:`~loper_analysis.impedance.identification.pair_windows` with
    ``params`` and ``window_options``, those of the mean window); ``null_pairs``: the fit's null pairs;
    ``settings``: the identification settings (``null_pair_components``, ``lower``, ``upper``).
    """
    return jackknife_sd(
        window,
        estimate,
        pair_windows(pairs, params, **window_options),
        null_pairs,
        settings.null_pair_components,
        covariance_scale=float(pairs.get("covariance_scale", 1.0)),
        lower=settings.lower,
        upper=settings.upper,
    )
