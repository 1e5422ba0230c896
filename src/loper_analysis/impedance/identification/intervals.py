"""95 % confidence intervals of K and D: the quantile, its degrees of freedom and the bounds.

An interval is ``estimate +- t_{0.975, dof} * sd`` (``sd`` from the
linearised covariance, :mod:`.fit` and :mod:`.null_pairs`), intersected with
the bounds of the parameter (K, D >= 0 is the physical limit of the model,
the upper bounds are the fit's own): an interval that would reach below the
lower bound starts at it, one that would pass the upper bound ends at it.
The intersection keeps the truth whenever the unbounded interval held it (the
truth lies inside the bounds), so the coverage is unchanged; it only drops
values the fit cannot return. An estimate on the lower bound gets
``[lower, lower + t sd]`` (method: ``docs/identification.md``, "95 %
confidence intervals").

``dof``: the residuals' ``m - 6`` for a white fit; for a fit whose covariance
comes from ``N`` null pairs, ``N - 1``, the degrees of freedom of their sample
covariance (:func:`loper_analysis.impedance.identification.refit_with_null_pairs`).
"""

from __future__ import annotations

import numpy as np
from scipy.special import (
    fdtri,  # quantile of the F distribution (what scipy.stats.f.ppf calls)
    stdtrit,  # Student's t quantile (what scipy.stats.t.ppf calls; scipy.stats costs ~0.5 s to import)
)

from loper_analysis.errors import LoperInputError

__all__ = ["CI_LEVEL", "t_quantile", "f_quantile", "bounded_interval", "sandwich_covariance"]

#: Confidence level of the reported intervals.
CI_LEVEL: float = 0.95


def t_quantile(dof: float, level: float = CI_LEVEL) -> float:
    """Two-sided quantile of Student's t: ``t_{(1 + level) / 2, dof}`` (``dof`` >= 1; infinite: the normal's)."""
    if not (dof >= 1):
        raise LoperInputError(f"degrees of freedom of a confidence interval must be >= 1, got {dof}")
    if not 0 < level < 1:
        raise LoperInputError(f"confidence level must lie in (0, 1), got {level}")
    return float(stdtrit(dof, 0.5 + level / 2))


def f_quantile(dof_numerator: float, dof_denominator: float, level: float) -> float:
    """Quantile ``level`` of the F distribution with the given degrees of freedom (each >= 1).

    The variance ratio ``s1^2 / s2^2`` of two independent estimates of one variance, with ``dof_numerator`` and
    ``dof_denominator`` degrees of freedom, exceeds it with probability ``1 - level``.
    """
    if not (dof_numerator >= 1 and dof_denominator >= 1):
        raise LoperInputError(
            f"degrees of freedom of an F quantile must be >= 1, got {dof_numerator}, {dof_denominator}"
        )
    if not 0 < level < 1:
        raise LoperInputError(f"F quantile level must lie in (0, 1), got {level}")
    return float(fdtri(dof_numerator, dof_denominator, level))


def bounded_interval(estimate, sd, dof: float, lower, upper, level: float = CI_LEVEL) -> tuple[np.ndarray, np.ndarray]:
    """Low and high ends of ``estimate +- t sd`` intersected with ``[lower, upper]``.

    Parameters
    ----------
    estimate, sd, lower, upper : (p,) array_like
        Estimates inside their bounds, their standard deviations (>= 0; inf:
        no information, the interval is the bound range), and the bounds.
    dof : float
        Degrees of freedom of the t quantile.
    level : float
        Confidence level.

    Returns
    -------
    (numpy.ndarray, numpy.ndarray)
        Low and high ends (p,), ``lower <= low <= estimate <= high <= upper``.
    """
    est, s = np.asarray(estimate, dtype=float), np.asarray(sd, dtype=float)
    lb, ub = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if not (est.shape == s.shape == lb.shape == ub.shape):
        raise LoperInputError(
            f"estimate, sd and bounds must have one shape, got {est.shape}, {s.shape}, {lb.shape}, {ub.shape}"
        )
    if np.any(np.isnan(s)) or np.any(s < 0):
        raise LoperInputError(f"standard deviations must be >= 0 (inf allowed), got {s}")
    if np.any(est < lb) or np.any(est > ub):
        raise LoperInputError(f"estimates {est} must lie inside their bounds [{lb}, {ub}]")
    half = t_quantile(dof, level) * s
    with np.errstate(invalid="ignore"):
        low = np.where(np.isfinite(half), est - half, -np.inf)
        high = np.where(np.isfinite(half), est + half, np.inf)
    return np.clip(low, lb, ub), np.clip(high, lb, ub)


def sandwich_covariance(jacobian, noise_cov, weight=None) -> np.ndarray:
    """Covariance (p, p) of the linearised weighted least-squares estimator: ``M C M^T``.

    ``M = (J^T J)^+ J^T W``; ``jacobian`` ``J`` (m, p) of the weighted
    residuals ``W e`` with respect to the parameters, ``noise_cov`` ``C``
    (m, m) of the unweighted errors ``e``, ``weight`` ``W`` (m, m; None: the
    identity). For ``W`` = I and ``C = s^2 I`` it is the ordinary ``s^2 (J^T J)^-1``.
    """
    J = np.asarray(jacobian, dtype=float)
    C = np.asarray(noise_cov, dtype=float)
    m = J.shape[0]
    if J.ndim != 2 or C.shape != (m, m) or (weight is not None and np.shape(weight) != (m, m)):
        raise LoperInputError(
            f"sandwich: jacobian (m, p), noise_cov and weight (m, m) expected, got {J.shape}, "
            f"{C.shape}, {np.shape(weight)}"
        )
    M = np.linalg.pinv(J.T @ J, rcond=1e-13) @ J.T
    if weight is not None:
        M = M @ np.asarray(weight, dtype=float)
    return M @ C @ M.T
