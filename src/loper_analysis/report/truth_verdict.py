"""The rule of the front page's truth verdicts: a calibration run's share against the target, this run's against it.

A run of a few synthetic subjects has too few fits to decide whether its intervals hold the truth in 95 % of
fits or its estimates lie within tolerance as often as the target asks. The verdicts rest on a calibration run
of many fits at the same design (:mod:`loper_analysis.report.calibration`); this run's own counts check that the
chain that ran is the chain that was calibrated:

* with a calibration of this run's design (its fingerprint and tolerance this run's), a verdict is green when
  the calibration's share meets the target (its Clopper-Pearson 95 % interval reaches the target's range) and
  this run's count agrees with the calibration's share (two-sided binomial test, p >= :data:`CONSISTENCY_P`);
  red otherwise: a design whose correct chain misses the target, or a run whose counts a chain like the
  calibrated one would give less than once in a thousand runs (a broken chain);
* without one (none named, or made at another design), this run's own counts stand alone: too few to decide
  (grey), unless they alone reject the target (p < :data:`REJECT_P`: red).

The intervals' verdict pools K and D over the joints (target :data:`~loper_analysis.report.headline.COVERAGE_TARGET`
around the nominal 95 %). The estimates' judges K and D each, pooled over the joints, by the chain alone: how
often they fall within tolerance is the design's precision, which the calibration measures and the page states
against :data:`~loper_analysis.report.headline.WITHIN_TOLERANCE_TARGET`; the verdict is green when this run's
counts agree with the calibration's (a correct chain at this design), red when they do not, grey without a
calibration of this design.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pandas as pd
from scipy.stats import binom, binomtest

from loper_analysis.checks import integer
from loper_analysis.errors import LoperInputError
from loper_analysis.report.calibration import Calibration
from loper_analysis.report.headline import COVERAGE_TARGET, PARAMETER_KINDS, WITHIN_TOLERANCE_TARGET

__all__ = [
    "BASES",
    "CONSISTENCY_P",
    "REJECT_P",
    "ShareCheck",
    "TruthVerdicts",
    "share_check",
    "truth_verdicts",
]

#: This run's count agrees with the calibration's share when a two-sided binomial test gives at least this: a
#: chain like the calibrated one is called broken in one run of a thousand. The fits of one subject share its
#: gait and K and D share a fit, so the counts scatter somewhat more than the binomial says: the level is strict.
CONSISTENCY_P = 0.001
#: Without a calibration of this design, this run's own counts reject the target below this (one-sided binomial
#: probability at the target's nearer end).
REJECT_P = 0.001
#: What the verdicts rest on: ``calibration`` (a calibration of this design), ``other_design`` (a calibration of
#: another design), ``none`` (no calibration named).
BASES: tuple[str, ...] = ("calibration", "other_design", "none")


@dataclass(frozen=True)
class ShareCheck:
    """One share judged: how many of this run's ``total`` (``n``) and of the calibration's meet the criterion.

    Attributes
    ----------
    n, total : int
        This run's count and its fits (intervals: two per joint fit).
    target : (float, float)
        The share's target range (``(0.9, 1.0)``: at least 90 %).
    calibration : (int, int) or None
        The calibration's count and fits; None: the verdict rests on this run alone.
    calibration_interval : (float, float) or None
        The Clopper-Pearson 95 % interval of the calibration's share.
    target_met : bool or None
        Whether that interval reaches the target's range.
    p_consistent : float or None
        Two-sided binomial probability of this run's count under the calibration's share.
    p_reject : float
        This run alone against the target: the one-sided binomial probability of its count or one further
        from the target at the target's nearer end (1 inside the range; NaN without fits).
    verdict : bool or None
        True (green), False (red) or None (grey: too few to decide).
    """

    n: int
    total: int
    target: tuple[float, float]
    calibration: tuple[int, int] | None
    calibration_interval: tuple[float, float] | None
    target_met: bool | None
    p_consistent: float | None
    p_reject: float
    verdict: bool | None


def _reject_p(n: int, total: int, target: tuple[float, float]) -> float:
    """One-sided binomial probability of ``n`` of ``total`` or fewer at the target's low end, or as many or more
    at its high end (the nearer); 1 for a share inside the range."""
    if total == 0:
        return math.nan
    low, high = target
    share = n / total
    if share < low:
        return float(binom.cdf(n, total, low))
    if share > high:
        return float(binom.sf(n - 1, total, high))
    return 1.0


def share_check(
    n: int,
    total: int,
    target: tuple[float, float],
    calibration: tuple[int, int] | None,
    target_decides: bool = True,
) -> ShareCheck:
    """Judge one share by the rule of this module.

    Parameters
    ----------
    n, total : int
        This run's count and its fits.
    target : (float, float)
        The share's target range, ``0 <= low <= high <= 1``.
    calibration : (int, int) or None
        The calibration's count and fits (``total >= 1``); None: no calibration of this design.
    target_decides : bool
        Whether the target decides the verdict (the intervals': a correct chain's intervals hold the truth about
        95 % of the time at any design). False for a share that measures the design's precision (the estimates
        within tolerance): the verdict is then this run's agreement with the calibration alone, green for a
        correct chain whatever the design's share, and grey without a calibration of this design (a correct
        chain at an imprecise design and a broken chain cannot be told apart by the run's own few fits).

    Returns
    -------
    ShareCheck
        The numbers and the verdict.
    """
    total = integer("total", total, minimum=0)
    n = integer("n", n, minimum=0)
    if n > total:
        raise LoperInputError(f"n must be <= total = {total}, got {n}")
    low, high = target
    p_reject = _reject_p(n, total, target)
    if calibration is None:
        rejected = target_decides and total > 0 and p_reject < REJECT_P
        return ShareCheck(n, total, target, None, None, None, None, p_reject, False if rejected else None)
    c_n, c_total = integer("calibration count", calibration[0], minimum=0), calibration[1]
    c_total = integer("calibration fits", c_total, minimum=1)
    if c_n > c_total:
        raise LoperInputError(f"the calibration's count must be <= its fits = {c_total}, got {c_n}")
    ci = binomtest(c_n, c_total).proportion_ci(confidence_level=0.95, method="exact")
    interval = (float(ci.low), float(ci.high))
    target_met = interval[0] <= high and interval[1] >= low
    p_consistent = float(binomtest(n, total, c_n / c_total).pvalue) if total else math.nan
    consistent = not total or p_consistent >= CONSISTENCY_P
    verdict = (target_met and consistent) if target_decides else consistent
    return ShareCheck(n, total, target, (c_n, c_total), interval, target_met, p_consistent, p_reject, verdict)


@dataclass(frozen=True)
class TruthVerdicts:
    """The truth verdicts of a run.

    ``basis``: what they rest on (:data:`BASES`); ``calibration``: the calibration named (None: none);
    ``fingerprint``: this run's design fingerprint; ``intervals``: the 95 % intervals holding the truth, K and D
    of every joint fit pooled; ``within``: parameter -> its estimates within tolerance.
    """

    basis: str
    calibration: Calibration | None
    fingerprint: str
    intervals: ShareCheck
    within: dict[str, ShareCheck]

    @property
    def estimates(self) -> bool | None:
        """The estimates' verdict: red when a parameter's is, green when both are, else grey."""
        marks = [c.verdict for c in self.within.values()]
        return False if False in marks else (True if all(marks) else None)


def truth_verdicts(truth: pd.DataFrame, calibration: Calibration | None, fingerprint: str) -> TruthVerdicts:
    """The truth verdicts of a run's truth recovery, on the calibration when it is of this run's design.

    Parameters
    ----------
    truth : pandas.DataFrame
        :func:`loper_analysis.report.headline.truth_recovery` of the run (``n_fits``, ``K_n_truth_in_ci95``,
        ``K_n_within_tolerance`` and D's, per joint).
    calibration : Calibration or None
        The calibration run named by the configuration
        (:func:`~loper_analysis.report.calibration.calibration_from_table`); None: none named.
    fingerprint : str
        This run's design fingerprint (:func:`~loper_analysis.report.calibration.design_fingerprint`).

    Returns
    -------
    TruthVerdicts
        The intervals' and the estimates' verdicts.
    """
    if calibration is None:
        basis = "none"
    elif calibration.design_fingerprint != fingerprint:
        basis = "other_design"
    else:
        basis = "calibration"
    used = calibration if basis == "calibration" else None
    n_fits = int(truth["n_fits"].sum())
    inside = int(sum(truth[f"{p}_n_truth_in_ci95"].sum() for p in PARAMETER_KINDS))
    intervals = share_check(
        inside,
        2 * n_fits,
        COVERAGE_TARGET,
        None if used is None else (used.total("n_truth_in_ci95"), used.total("n_fits")),
    )
    within = {
        p: share_check(
            int(truth[f"{p}_n_within_tolerance"].sum()),
            n_fits,
            (WITHIN_TOLERANCE_TARGET, 1.0),
            None if used is None else (used.total("n_within_tolerance", (p,)), used.total("n_fits", (p,))),
            target_decides=False,
        )
        for p in PARAMETER_KINDS
    }
    return TruthVerdicts(basis, calibration, fingerprint, intervals, within)
