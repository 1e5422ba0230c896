"""The inter-joint (bi-articular) stiffnesses of a fit as table rows, one per coupling, with their status.

* :func:`identification_tolerance` - the study's tolerance on a K or D of a given size, the bar a coupling's
  interval must clear (the planner's verdict takes the same);
* :func:`coupling_rows` - the rows (:data:`COUPLING_COLUMNS`) of a fit with couplings.

A coupling ``K_<coupling>`` (N·m/rad) adds the symmetric stiffness ``-K (dtheta_j1, dtheta_j2)`` between two
neighbouring joints to the impedance feedback (``docs/identification.md``, "Inter-joint couplings").
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from loper_analysis.constants import COUPLING_PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE
from loper_analysis.impedance.identification.fit import ImpedanceFit
from loper_analysis.impedance.identification.parameters import COUPLING_BOUNDS_NM_PER_RAD
from loper_analysis.impedance.identification.status import AT_BOUND_FRACTION

__all__ = ["COUPLING_COLUMNS", "identification_tolerance", "coupling_rows"]

#: Columns of ``results/impedance/{subject}/{onset}.couplings.tsv`` and ``results/impedance/couplings.tsv``.
COUPLING_COLUMNS: tuple[str, ...] = (
    "subject",
    "onset_ms",
    "coupling",
    "K_nm_per_rad",
    "K_ci95_low_nm_per_rad",
    "K_ci95_high_nm_per_rad",
    "K_se_nm_per_rad",
    "ci_dof",
    "tolerance_nm_per_rad",
    "n_strides",
    "K_true_nm_per_rad",
    "K_error_nm_per_rad",
    "status",
    "reason",
)


def identification_tolerance(kind: str, planned: float) -> float:
    """The tolerance (N·m/rad for a stiffness ``kind`` ``"K"``, a coupling's too; N·m·s/rad for ``"D"``) within
    which a design must place a parameter of size ``planned`` to identify it: the study's tolerance on the
    truth, ``max(relative * |planned|, absolute)`` with (10 %, 2 N·m/rad) for K and (15 %, 0.05 N·m·s/rad) for D
    (:data:`~loper_analysis.impedance.identification.across_subjects.TRUTH_TOLERANCE`). A coupling of 0 gets
    2 N·m/rad."""
    if kind not in TRUTH_TOLERANCE:
        raise LoperInputError(f"parameter kind must be one of {sorted(TRUTH_TOLERANCE)}, got {kind!r}")
    relative, absolute = TRUTH_TOLERANCE[kind]
    return max(relative * abs(float(planned)), absolute)


def _status(estimate: float, low: float, high: float, fit: ImpedanceFit, bounds) -> tuple[str, str, float]:
    """Status, reason and tolerance (N·m/rad) of one coupling: ``failed`` when the fit did not converge;
    ``not_identifiable`` on a bound or when its 95 % interval's half-width exceeds the study's tolerance at its
    size (:func:`identification_tolerance`: the data cannot place it within the tolerance the study holds every K
    to); else ``ok``."""
    tolerance = identification_tolerance("K", estimate)
    if not fit.success:
        return "failed", f"the fit did not converge: {fit.message}", tolerance
    span = bounds[1] - bounds[0]
    for bound in bounds:
        if abs(estimate - bound) <= AT_BOUND_FRACTION * span:
            return "not_identifiable", f"on its bound {bound:g} N·m/rad", tolerance
    half = 0.5 * (high - low)
    if not np.isfinite(half) or half > tolerance:
        return (
            "not_identifiable",
            f"95 % CI half-width {half:.3g} N·m/rad exceeds the study's tolerance {tolerance:.3g} N·m/rad at this "
            "size (max(10 %, 2 N·m/rad)): the design cannot place it; loper-analysis plan --couplings says how many "
            "strides, or a second rod (planning.shank_pulse_force_n), would",
            tolerance,
        )
    return "ok", "", tolerance


def coupling_rows(
    fit: ImpedanceFit,
    subject: str,
    onset_ms: int,
    n_strides: int,
    truth: Mapping | None = None,
    *,
    bounds_nm_per_rad: tuple[float, float] = COUPLING_BOUNDS_NM_PER_RAD,
    note: str = "",
    interval_notes: Mapping[str, str] | None = None,
) -> pd.DataFrame:
    """One row per inter-joint coupling of ``fit`` (its parameters after the six; columns :data:`COUPLING_COLUMNS`).

    ``truth``: a synthetic subject's ``{name: {"K": ..}}`` at this onset (None for a recorded one: truth and error
    left empty); a coupling it does not name is 0 (the synthetic lab's legs have none). ``bounds_nm_per_rad``:
    the fit's bounds of a coupling (low, high); ``note`` is appended to every row's reason, ``interval_notes``
    (parameter name -> text, e.g. that its interval comes from the perturbed pairs' scatter) to its own. Status:
    :func:`_status`. No coupling: no row.
    """
    rows = []
    for i, name in enumerate(fit.parameters):
        if name not in COUPLING_PARAMETERS:
            continue
        estimate, low, high = float(fit.estimate[i]), float(fit.ci95_low[i]), float(fit.ci95_high[i])
        status, reason, tolerance = _status(estimate, low, high, fit, bounds_nm_per_rad)
        row = {
            "subject": subject,
            "onset_ms": int(onset_ms),
            "coupling": name[2:],
            "K_nm_per_rad": estimate,
            "K_ci95_low_nm_per_rad": low,
            "K_ci95_high_nm_per_rad": high,
            "K_se_nm_per_rad": float(fit.sd[i]),
            "ci_dof": int(fit.ci_dof),
            "tolerance_nm_per_rad": tolerance,
            "n_strides": int(n_strides),
            "status": status,
            "reason": "; ".join(r for r in (reason, (interval_notes or {}).get(name, ""), note) if r),
        }
        if truth is not None:
            true = float(truth.get(name[2:], {"K": 0.0})["K"])
            row["K_true_nm_per_rad"] = true
            row["K_error_nm_per_rad"] = estimate - true
        rows.append(row)
    return pd.DataFrame(rows, columns=list(COUPLING_COLUMNS))
