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
  :func:`strides_needed` and :func:`target_answer` - how many strides a target half-width needs.

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
from loper_analysis.constants import JOINTS, PARAMETER_UNITS, PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    t_quantile,
)
from loper_analysis.planning.covariance import StrideCovariance, stride_counts
from loper_analysis.planning.window import PlanSettings

__all__ = [
    "MAX_ANSWERED_STRIDES",
    "PLAN_COLUMNS",
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

#: A target that needs more perturbed strides than this is answered as "more than" it.
MAX_ANSWERED_STRIDES: int = 1_000_000


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

    ``predicted_sd = sqrt(sd_1^2 / N + b / N^2)`` (:meth:`StrideCovariance.sd_of`) and
    ``ci95_half_width = t * predicted_sd``
    (Student's t at 97.5 % with the fit's degrees of freedom,
    :meth:`StrideCovariance.t95`: ``N - 1`` by default), both in ``unit``;
    ``ci95_half_width_pct`` relative to the planned value (%; NaN for a
    planned value of 0). Rows: hip, knee, ankle x K, D x ``n_strides``.
    """
    counts = stride_counts(n_strides, subject or "plan")
    rows = []
    for j, joint in enumerate(JOINTS):
        for k, kind in enumerate(("K", "D")):
            i = 2 * j + k
            planned = float(stride_cov.impedance[i])
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
                        "unit": PARAMETER_UNITS[PARAMETERS[i]],
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
    return pd.DataFrame(rows, columns=list(PLAN_COLUMNS))


def unplanned_rows(
    n_strides: Sequence[int], onset_ms: float, note: str, subject: str = "", settings: PlanSettings = PlanSettings()
) -> pd.DataFrame:
    """Rows of :data:`PLAN_COLUMNS` for an onset that cannot be planned: predictions empty, ``note`` says why."""
    counts = stride_counts(n_strides, subject or "plan")
    rows = [
        {
            "subject": subject,
            "onset_ms": float(onset_ms),
            "joint": joint,
            "parameter": kind,
            "unit": PARAMETER_UNITS[f"{kind}_{joint}"],
            "n_strides": n,
            "pulse_force_n": float(settings.pulse_force_n),
            "pulse_duration_s": float(settings.pulse_duration_s),
            "shank_pulse_force_n": float(settings.shank_pulse_force_n),
            "note": note,
        }
        for joint in JOINTS
        for kind in ("K", "D")
        for n in counts
    ]
    return pd.DataFrame(rows, columns=list(PLAN_COLUMNS))


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
    if joint not in JOINTS:
        raise LoperInputError(f"target joint must be one of {JOINTS}, got {joint!r}")
    if parameter not in ("K", "D"):
        raise LoperInputError(f"target parameter must be 'K' or 'D', got {parameter!r}")
    if (percent is None) == (half_width is None):
        raise LoperInputError("give exactly one target: percent or half_width")
    i = PARAMETERS.index(f"{parameter}_{joint}")
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
    i = PARAMETERS.index(f"{parameter}_{joint}")
    unit, planned = PARAMETER_UNITS[PARAMETERS[i]], float(stride_cov.impedance[i])
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
