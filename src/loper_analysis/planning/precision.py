"""Planning an experiment: the precision of K and D before anyone walks (method: ``docs/planning.md``).

The null-pair fit (:mod:`loper_analysis.impedance.identification.null_pairs`) takes the
covariance of its estimate by the sandwich ``cov = M C M^T`` with
``M = (W J)^+ W``, ``C = cov(E) / N`` (``E`` the prediction errors of pairs
one by one, ``N`` the perturbed strides averaged, ``W`` the projection of the
null pairs' dominant shapes, ``J`` the sensitivity of the model response to K
and D). ``E`` are the errors of the *perturbed* pairs: each stride answers
the pulse about its own course, which pairs without a pulse (null pairs)
cannot show. From a pilot subject's null pairs, its perturbed pairs at the
onset (when it has them), a planned pulse and a planned impedance the
planner predicts the SD and the 95 % CI half-width of every K and D for any
number of perturbed strides, and the number of strides a target half-width
needs.

The planner's parts, each in its module:

* :mod:`loper_analysis.planning.inputs` - the force the rods apply for a planned pulse and the pilot's
  perturbed pairs at an onset;
* :mod:`loper_analysis.planning.window` - the settings and the identification window of the planned
  experiment;
* :mod:`loper_analysis.planning.covariance` - the covariance of (K, D) for one perturbed stride, for either
  counterfactual, over the pilot's stretches, pooled over onsets;
* here: :func:`precision_table` - predicted SD and 95 % half-width per joint, parameter and stride count;
  :func:`strides_needed` and :func:`target_answer` - how many strides a target half-width needs;
  :func:`identification_verdict` - whether a design identifies a
  parameter (the plan's verdict on the inter-joint couplings, :attr:`PlanSettings.couplings`).

The identification's own functions build the window, the Jacobian, the
null-pair errors and the projection
(:func:`~loper_analysis.impedance.identification.prepare_window`,
:func:`~loper_analysis.impedance.identification.response_jacobian`,
:func:`~loper_analysis.impedance.identification.null_pair_errors`,
:func:`~loper_analysis.impedance.identification.nuisance_projection`), so the
prediction is the fit's own covariance formula.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.checks import number
from loper_analysis.constants import COUPLING_UNIT, JOINTS, PARAMETER_UNITS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    t_quantile,
)
from loper_analysis.impedance.identification.coupling_rows import identification_tolerance
from loper_analysis.planning.covariance import StrideCovariance, stride_counts
from loper_analysis.planning.window import PlanSettings

__all__ = [
    "MAX_ANSWERED_STRIDES",
    "PLAN_COLUMNS",
    "COUPLING_PLAN_COLUMNS",
    "IDENTIFIED",
    "NOT_IDENTIFIED",
    "identification_verdict",
    "precision_table",
    "strides_needed",
    "target_answer",
    "unplanned_rows",
]

#: Columns of the plan table (one row per joint x parameter x onset x stride count).
PLAN_COLUMNS: tuple[str, ...] = (
    "subject",
    "onset_ms",
    "joint",
    "parameter",
    "unit",
    "n_strides",
    "planned_value",
    "predicted_sd",
    "ci95_half_width",
    "ci95_half_width_pct",
    "pulse_force_n",
    "pulse_duration_s",
    "shank_pulse_force_n",
    "n_null_pairs",
    "n_perturbed_pairs",
    "scatter",
    "note",
)

#: Columns a plan with inter-joint couplings (:attr:`PlanSettings.couplings`) adds to :data:`PLAN_COLUMNS`, on
#: every row: the tolerance the verdict holds the predicted half-width to (``unit``), the verdict
#: (:func:`identification_verdict`) and the fewest perturbed strides whose half-width meets that tolerance
#: (NaN: more than :data:`MAX_ANSWERED_STRIDES`).
COUPLING_PLAN_COLUMNS: tuple[str, ...] = ("tolerance", "verdict", "strides_to_identify")
#: The verdicts of :func:`identification_verdict`.
IDENTIFIED, NOT_IDENTIFIED = "identified", "not identified"

#: A target that needs more perturbed strides than this is answered as "more than" it.
MAX_ANSWERED_STRIDES: int = 1_000_000


def identification_verdict(half_width: float, tolerance: float) -> str:
    """:data:`IDENTIFIED` when the predicted 95 % CI half-width is at most ``tolerance`` (same unit), else
    :data:`NOT_IDENTIFIED`.

    The rule: the fit's 95 % interval is ``estimate +- t SD``; when ``t SD <= tolerance``, an estimate that
    scatters as predicted (unbiased, normal) lies within the tolerance of the truth in 95 % of experiments of this
    design, the standard the study holds every K and D to. A design that fails it may still tell a large coupling
    from 0; it cannot place one of the size a spring-like leg allows (``|K_hip_knee| <= sqrt(K_hip K_knee)``,
    12.8 N·m/rad for a hip of 55 and a knee of 3 N·m/rad) within the study's tolerance.
    """
    return IDENTIFIED if float(half_width) <= float(tolerance) else NOT_IDENTIFIED


def precision_table(
    stride_cov: StrideCovariance,
    n_strides: Sequence[int],
    onset_ms: float,
    subject: str = "",
    settings: PlanSettings = PlanSettings(),
    by_count: Mapping[int, StrideCovariance] | None = None,
) -> pd.DataFrame:
    """Predicted SD and 95 % CI half-width per joint, parameter and stride count (columns :data:`PLAN_COLUMNS`).

    ``by_count``: covariances for some stride counts (:func:`stretch_covariances`) that replace
    ``stride_cov`` in those counts' rows.

    With inter-joint couplings (``stride_cov.couplings``, from :attr:`PlanSettings.couplings`) each coupling
    gets rows too (``joint`` the pair, e.g. ``hip_knee``; ``parameter`` ``K``; unit N·m/rad), and every row
    the columns :data:`COUPLING_PLAN_COLUMNS`: ``tolerance``
    (:func:`~loper_analysis.impedance.identification.coupling_rows.identification_tolerance` of its planned
    value), ``verdict`` (:func:`identification_verdict` of its half-width) and ``strides_to_identify``
    (:func:`strides_needed` for a half-width of ``tolerance``, from ``stride_cov``).

    ``predicted_sd = sqrt(sd_1^2 / N + b / N^2)`` (:meth:`StrideCovariance.sd_of`) and
    ``ci95_half_width = t * predicted_sd``
    (Student's t at 97.5 % with the fit's degrees of freedom,
    :meth:`StrideCovariance.t95`: ``N - 1`` by default), both in ``unit``;
    ``ci95_half_width_pct`` relative to the planned value (%; NaN for a
    planned value of 0). Rows: hip, knee, ankle x K, D x ``n_strides``, then each coupling x ``n_strides``.
    """
    counts = stride_counts(n_strides, subject or "plan")
    coupled = bool(stride_cov.couplings)
    rows = []
    for i, name in enumerate(stride_cov.parameters):
        kind, joint = name.split("_", 1)
        planned = float(stride_cov.impedance[i])
        if coupled:
            tolerance = identification_tolerance(kind, planned)
            needed = strides_needed(stride_cov, joint, kind, half_width=tolerance)
        for n in counts:
            sc = (by_count or {}).get(n, stride_cov)
            sd = float(sc.sd_of(n)[i])
            half = sc.t95(n) * sd
            rows.append(
                {
                    "subject": subject,
                    "onset_ms": float(onset_ms),
                    "joint": joint,
                    "parameter": kind,
                    "unit": PARAMETER_UNITS.get(name, COUPLING_UNIT),
                    "n_strides": n,
                    "planned_value": planned,
                    "predicted_sd": sd,
                    "ci95_half_width": half,
                    "ci95_half_width_pct": 100.0 * half / abs(planned) if planned != 0 else np.nan,
                    "pulse_force_n": float(settings.pulse_force_n),
                    "pulse_duration_s": float(settings.pulse_duration_s),
                    "shank_pulse_force_n": float(settings.shank_pulse_force_n),
                    "n_null_pairs": sc.n_null_pairs,
                    "n_perturbed_pairs": sc.n_perturbed_pairs,
                    "scatter": sc.scatter,
                    "note": sc.note,
                }
            )
            if coupled:
                rows[-1] |= {
                    "tolerance": tolerance,
                    "verdict": identification_verdict(half, tolerance),
                    "strides_to_identify": float(needed) if needed <= MAX_ANSWERED_STRIDES else np.nan,
                }
    return pd.DataFrame(rows, columns=list(PLAN_COLUMNS + (COUPLING_PLAN_COLUMNS if coupled else ())))


def unplanned_rows(
    n_strides: Sequence[int], onset_ms: float, note: str, subject: str = "", settings: PlanSettings = PlanSettings()
) -> pd.DataFrame:
    """Rows of :data:`PLAN_COLUMNS` for an onset that cannot be planned: predictions empty, ``note`` says why
    (with ``settings.couplings`` also the couplings' rows and :data:`COUPLING_PLAN_COLUMNS`, empty)."""
    counts = stride_counts(n_strides, subject or "plan")
    pairs = [(joint, kind) for joint in JOINTS for kind in ("K", "D")] + [(c, "K") for c in settings.couplings]
    rows = [
        {
            "subject": subject,
            "onset_ms": float(onset_ms),
            "joint": joint,
            "parameter": kind,
            "unit": PARAMETER_UNITS.get(f"{kind}_{joint}", COUPLING_UNIT),
            "n_strides": n,
            "pulse_force_n": float(settings.pulse_force_n),
            "pulse_duration_s": float(settings.pulse_duration_s),
            "shank_pulse_force_n": float(settings.shank_pulse_force_n),
            "note": note,
        }
        for joint, kind in pairs
        for n in counts
    ]
    extra = COUPLING_PLAN_COLUMNS if settings.couplings else ()
    return pd.DataFrame(rows, columns=list(PLAN_COLUMNS + extra))


def strides_needed(
    stride_cov: StrideCovariance,
    joint: str,
    parameter: str,
    *,
    percent: float | None = None,
    half_width: float | None = None,
) -> int:
    """Fewest perturbed strides whose 95 % CI half-width on ``parameter`` of ``joint`` meets the target.

    Give either ``percent`` (of the planned value, e.g. 15 for +-15 %) or
    ``half_width`` (absolute, N·m/rad or N·m·s/rad): the smallest ``N`` with
    ``t_N sd_1 / sqrt(N) <= target`` (``t_N`` :meth:`StrideCovariance.t95`;
    with a fixed t, ``N = ceil((t sd_1 / target)^2)``). With a ``1/N^2``
    part ``b`` (the conditional counterfactual) and a fixed t, the smallest
    ``N`` with ``t^2 (sd_1^2 / N + b / N^2) <= target^2``.
    """
    joints = JOINTS + stride_cov.couplings
    if joint not in joints:
        raise LoperInputError(f"target joint must be one of {joints}, got {joint!r}")
    if parameter not in ("K", "D") or (joint not in JOINTS and parameter != "K"):
        raise LoperInputError(
            f"target parameter must be 'K' or 'D' ('K' for an inter-joint coupling), got {parameter!r}"
        )
    if (percent is None) == (half_width is None):
        raise LoperInputError("give exactly one target: percent or half_width")
    i = stride_cov.parameters.index(f"{parameter}_{joint}")
    planned = float(stride_cov.impedance[i])
    if percent is not None:
        pct = number("target percent", percent)
        if pct <= 0:
            raise LoperInputError(f"target percent must be > 0, got {pct:g}")
        if planned == 0:
            raise LoperInputError(
                f"a relative target needs a planned {parameter} of the {joint} other than 0; "
                "give an absolute half-width"
            )
        target = pct / 100.0 * abs(planned)
    else:
        target = number("target half_width", half_width)
        if target <= 0:
            raise LoperInputError(f"target half_width must be > 0, got {target:g}")
    sd1 = float(stride_cov.sd[i])
    if stride_cov.spread_covariance is not None and stride_cov.dof is not None:
        a, b = (float(v[i]) for v in stride_cov.variance_terms())
        c = (target / stride_cov.t95(2)) ** 2
        n = int(math.ceil((a + math.sqrt(a * a + 4.0 * b * c)) / (2.0 * c) * (1 - 1e-12)))
        return max(1, n)

    def meets(n: int) -> bool:
        return stride_cov.t95(n) * sd1 / math.sqrt(n) <= target * (1 + 1e-12)

    # the half-width falls with N; t at N - 1 dof is at most t(1) = 12.7 and at least 1.96: below `low` no N
    # meets the target; from there up to the first N found to meet it, the smallest by bisection (a planned value
    # near 0 asks for astronomically many strides, too many to step through)
    low = max(1, int(math.ceil((t_quantile(10**6) * sd1 / target) ** 2 * (1 - 1e-12))) - 1)
    n = low
    while not meets(n):
        t = stride_cov.t95(n)
        n = n + 1 if not math.isfinite(t) else max(n + 1, int(math.ceil((t * sd1 / target) ** 2 * (1 - 1e-12))))
    while n - low > 1:
        mid = (low + n) // 2
        low, n = (low, mid) if meets(mid) else (mid, n)
    return n if n > 1 or not meets(1) else 1


def target_answer(
    stride_cov: StrideCovariance,
    joint: str,
    parameter: str,
    onset_ms: float,
    *,
    percent: float | None = None,
    half_width: float | None = None,
) -> str:
    """One sentence: how many perturbed strides a target half-width on ``parameter`` of ``joint`` needs."""
    n = strides_needed(stride_cov, joint, parameter, percent=percent, half_width=half_width)
    name = f"{parameter}_{joint}"
    i = stride_cov.parameters.index(name)
    unit, planned = PARAMETER_UNITS.get(name, COUPLING_UNIT), float(stride_cov.impedance[i])
    wanted = f"±{percent:g} %" if percent is not None else f"±{half_width:g} {unit}"
    if n > MAX_ANSWERED_STRIDES:
        return (
            f"{joint} {parameter} at {onset_ms:g} ms: {wanted} (95 % CI) needs more than {MAX_ANSWERED_STRIDES:,} "
            f"perturbed strides (planned {parameter} {planned:.3g} {unit}"
            + ("; a relative target on a value this close to 0: give a half_width instead)" if percent else ")")
        )
    reached = float(stride_cov.half_width(n)[i])
    return (
        f"{joint} {parameter} at {onset_ms:g} ms: {wanted} (95 % CI) needs {n} perturbed strides kept in the "
        f"average (planned {parameter} {planned:.3g} {unit}; predicted half-width at {n}: ±{reached:.3g} {unit}, "
        f"±{100 * reached / abs(planned) if planned else float('nan'):.3g} %)"
    )
