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
distribution with ``n - 1`` and ``N - 1`` degrees of freedom; a ratio beyond its quantile at
:data:`PAIR_SCATTER_LEVEL` says the null pairs' interval misses part of this fit's error, and
:func:`widen_to_pair_scatter` takes that parameter's interval from the jackknife instead (``docs/identification.md``,
"Fit status": "Intervals from the perturbed pairs' scatter").
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.fit import DEFAULT_LOWER, DEFAULT_UPPER, ImpedanceFit, response_jacobian
from loper_analysis.impedance.identification.intervals import bounded_interval, f_quantile
from loper_analysis.impedance.identification.null_pairs import nuisance_projection, null_pair_errors
from loper_analysis.impedance.identification.pair_averaging import pair_windows
from loper_analysis.impedance.identification.window import PreparedWindow, simulate_response
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = ["PAIR_SCATTER_LEVEL", "WIDENED", "jackknife_sd", "onset_jackknife", "widen_to_pair_scatter"]

#: A parameter whose perturbed pairs' jackknife variance exceeds its interval's by more than the F distribution's
#: quantile at this level gets its interval from the jackknife (:func:`widen_to_pair_scatter`): of the fits whose
#: perturbed pairs scatter as the null pairs say, 1 % per parameter.
PAIR_SCATTER_LEVEL: float = 0.99
#: What a row's reason says after ``{parameter}: `` (``K_ankle: ``) when that parameter's interval was widened.
WIDENED: str = "95 % CI from the perturbed pairs' scatter"


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


def widen_to_pair_scatter(
    fit: ImpedanceFit, jackknife: tuple, lower, upper, level: float = PAIR_SCATTER_LEVEL
) -> tuple[ImpedanceFit, dict[str, str]]:
    """``fit`` with the intervals of the parameters whose perturbed pairs scatter beyond them taken from that scatter.

    For each parameter ``i`` whose jackknife variance over the interval's, ``(sd_jk / sd)^2``, exceeds the F
    quantile at ``level`` with (``dof_jk``, ``fit.ci_dof``) degrees of freedom (the null pairs' interval misses an
    error the perturbed strides hold: each answers the pulse about its own course), its SD becomes ``sd_jk`` and
    its 95 % interval ``estimate +- t(dof_jk) sd_jk`` within the bounds; the estimate, the correlation and the other
    parameters stay. Parameters whose SDs are not both finite with ``sd > 0`` are left as they are.

    Parameters
    ----------
    fit : ImpedanceFit
        A fit with the null-pair noise model (its ``sd``, ``ci_dof``, ``parameters``).
    jackknife : (numpy.ndarray, int)
        The perturbed pairs' jackknife SD (p,) of every estimate and its degrees of freedom (:func:`jackknife_sd`).
    lower, upper : (p,) array_like
        The fit's bounds (N·m/rad, N·m·s/rad).
    level : float
        The F quantile's level, in (0, 1).

    Returns
    -------
    (ImpedanceFit, dict)
        The fit, and per widened parameter (its name, ``K_ankle``) the text its row's reason carries.
    """
    if not 0 < level < 1:
        raise LoperInputError(f"pair scatter level must lie in (0, 1), got {level}")
    sd, sd_jk = np.asarray(fit.sd, dtype=float), np.asarray(jackknife[0], dtype=float)
    dof = int(jackknife[1])
    if sd_jk.shape != sd.shape:
        raise LoperInputError(f"jackknife SD must hold the fit's {sd.shape[0]} parameters, got shape {sd_jk.shape}")
    limit = f_quantile(dof, fit.ci_dof, level)
    usable = np.isfinite(sd) & np.isfinite(sd_jk) & (sd > 0)
    ratio = np.where(usable, (sd_jk / np.where(usable, sd, 1.0)) ** 2, 0.0)
    wide = np.flatnonzero(ratio > limit)
    if not wide.size:
        return fit, {}
    lb, ub = np.broadcast_to(np.asarray(lower, float), sd.shape), np.broadcast_to(np.asarray(upper, float), sd.shape)
    new_sd, low, high = sd.copy(), np.array(fit.ci95_low, dtype=float), np.array(fit.ci95_high, dtype=float)
    new_sd[wide] = sd_jk[wide]
    low[wide], high[wide] = bounded_interval(fit.estimate[wide], sd_jk[wide], dof, lb[wide], ub[wide])
    notes = {}
    for i in wide:
        name = fit.parameters[i]
        unit = "N·m/rad" if name.startswith("K") else "N·m·s/rad"
        notes[name] = (
            f"{name}: {WIDENED} (jackknife SD {sd_jk[i]:.3g} {unit}, "
            f"{sd_jk[i] / sd[i]:.2g} times the null pairs' {sd[i]:.3g} {unit}: variance ratio {ratio[i]:.3g} above "
            f"F_{level:g}({dof}, {fit.ci_dof}) = {limit:.3g}, PAIR_SCATTER_LEVEL; t with {dof} degrees of freedom): "
            "the perturbed strides hold an error the null pairs do not show"
        )
    return replace(fit, sd=new_sd, ci95_low=low, ci95_high=high), notes
