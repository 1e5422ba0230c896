"""The across-subject mean of a parameter with a 95 % interval that carries each subject's own uncertainty.

A random-effects model: subject ``i``'s estimate is ``theta_i = mu + b_i + e_i`` with the between-subject
deviation ``b_i ~ N(0, tau^2)`` and the estimation error ``e_i ~ N(0, s_i^2)`` (``s_i`` the fit's standard
deviation). ``tau^2`` is estimated by DerSimonian and Laird's method of moments, ``mu`` as the mean weighted
by ``1 / (s_i^2 + tau^2)``, and its interval by the Hartung-Knapp-Sidik-Jonkman variance with Student's t on
``k - 1`` degrees of freedom, never narrower than the random-effects variance itself (``max(q, 1)``, the
modification of Röver, Knapp and Friede 2015): with few subjects the plain normal interval is too narrow.

With equal ``s_i`` the weighted mean is the plain mean and, when the subjects scatter more than their own
uncertainty, the interval is the t interval of the subjects' estimates; when they agree closely, it keeps the
width their own uncertainty gives (``t s / sqrt(k)``). A subject whose ``s_i`` is infinite (a fit without
information about the parameter) carries no weight. Method: ``docs/identification.md``, "Across subjects".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.intervals import CI_LEVEL, t_quantile

__all__ = ["GroupMean", "random_effects_mean"]


@dataclass(frozen=True)
class GroupMean:
    """The across-subject mean ``mean`` with its interval ``[ci95_low, ci95_high]`` (NaN: fewer than 2 subjects
    with information), the between-subject SD ``between_sd`` (``tau``, >= 0) and the number of subjects that
    carried weight, ``n_informative``; units those of the estimates."""

    mean: float
    ci95_low: float
    ci95_high: float
    between_sd: float
    n_informative: int


def random_effects_mean(estimates, sds, level: float = CI_LEVEL) -> GroupMean:
    """Random-effects mean of per-subject estimates (k,) with their standard deviations (k,) (same unit).

    Raises
    ------
    LoperInputError
        Shapes that differ, an estimate that is no finite number, or a negative or NaN standard deviation.
    """
    theta, s = np.asarray(estimates, dtype=float), np.asarray(sds, dtype=float)
    if theta.ndim != 1 or theta.shape != s.shape:
        raise LoperInputError(f"estimates and sds must be two vectors of one length, got {theta.shape}, {s.shape}")
    if not np.all(np.isfinite(theta)):
        raise LoperInputError(f"estimates must be finite numbers, got {theta}")
    if np.any(np.isnan(s)) or np.any(s < 0):
        raise LoperInputError(f"standard deviations must be >= 0 (inf: no information), got {s}")
    use = np.isfinite(s)
    theta, s = theta[use], s[use]
    k = int(theta.size)
    if k == 0:
        return GroupMean(math.nan, math.nan, math.nan, math.nan, 0)
    if k == 1:
        return GroupMean(float(theta[0]), math.nan, math.nan, math.nan, 1)
    var = np.maximum(s**2, np.finfo(float).tiny)
    w = 1.0 / var
    fixed = float(np.sum(w * theta) / np.sum(w))
    q = float(np.sum(w * (theta - fixed) ** 2))
    tau2 = max(0.0, (q - (k - 1)) / (np.sum(w) - np.sum(w**2) / np.sum(w)))
    w_star = 1.0 / (var + tau2)
    mu = float(np.sum(w_star * theta) / np.sum(w_star))
    q_hk = float(np.sum(w_star * (theta - mu) ** 2)) / (k - 1)
    half = t_quantile(k - 1, level) * math.sqrt(max(q_hk, 1.0) / float(np.sum(w_star)))
    return GroupMean(mu, mu - half, mu + half, math.sqrt(tau2), k)
