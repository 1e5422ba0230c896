"""Planning an experiment: the precision of K and D before anyone walks (method: ``docs/planning.md``).

The null-pair fit (:mod:`loper_analysis.identification.null_pairs`) takes the
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

* :func:`pulse_force_n` (from :mod:`loper_analysis.planning.inputs`) - the force the rods apply for a
  rectangular desired pulse: the device's closed loop (about 10 ms rise, 30 % overshoot), low-passed
  like the load cell;
* :func:`pilot_perturbed_pairs` (from :mod:`loper_analysis.planning.inputs`) - the pilot's
  perturbed pairs at an onset, one by one;
* :func:`planning_window` - the identification window of the planned
  experiment: the pilot's mean unperturbed swing as the reference, the pulse
  along the thigh normal;
* :func:`stride_covariance` - the covariance of (K, D) per joint for one
  perturbed stride (divide by ``N``), from the pilot's perturbed pairs (or
  its null pairs when it has none at the onset), for the study's matched stride;
* :func:`conditional_stride_covariance` - the same for the conditional
  counterfactual, from the pilot's cross-validated null pairs as the fit's
  intervals take them, with the candidates' share that does not average out;
* :func:`stretch_covariances` - for stride counts the pilot holds several
  times over: the mean of that covariance over the pilot's stretches of the
  planned size, each with only its own candidates;
* :func:`pool_onsets` - the perturbed pairs' excess scatter pooled over the
  pilot's onsets (steadier than one onset's dozen pairs);
* :func:`precision_table` - predicted SD and 95 % half-width per joint,
  parameter and stride count;
* :func:`strides_needed` and :func:`target_answer` - how many strides a target
  half-width needs.

The identification's own functions build the window, the Jacobian, the
null-pair errors and the projection
(:func:`~loper_analysis.identification.prepare_window`,
:func:`~loper_analysis.identification.response_jacobian`,
:func:`~loper_analysis.identification.null_pair_errors`,
:func:`~loper_analysis.identification.nuisance_projection`), so the
prediction is the fit's own covariance formula.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.checks import integer, number
from loper_analysis.constants import JOINTS, PARAMETER_UNITS, PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.identification import (
    FitBounds,
    PreparedWindow,
    check_interval_scatter,
    cross_validated_covariance,
    nuisance_projection,
    null_pair_errors,
    prepare_window,
    response_jacobian,
    t_quantile,
    window_options,
)
from loper_analysis.planning.inputs import pilot_onset_series, pilot_perturbed_pairs, pulse_force_n, trial_stretches
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = [
    "PLAN_COLUMNS",
    "MIN_PERTURBED_PAIRS",
    "PlanSettings",
    "StrideCovariance",
    "conditional_stride_covariance",
    "stretch_covariances",
    "pulse_force_n",
    "planning_window",
    "pilot_perturbed_pairs",
    "stride_covariance",
    "pool_onsets",
    "precision_table",
    "unplanned_rows",
    "strides_needed",
    "target_answer",
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
    "n_null_pairs",
    "n_perturbed_pairs",
    "scatter",
    "note",
)

#: A target that needs more perturbed strides than this is answered as "more than" it.
MAX_ANSWERED_STRIDES: int = 1_000_000
#: Fewest pilot perturbed pairs whose scatter the prediction takes (fewer: the null pairs' scatter, noted).
MIN_PERTURBED_PAIRS = 5


@dataclass(frozen=True)
class PlanSettings(FitBounds):
    """The planned pulse and the identification settings the prediction follows (config ``identification``).

    ``pulse_force_n`` (N, desired force) for ``pulse_duration_s`` (s) from the
    onset; ``window_before_s``, ``window_after_s``, ``initial_state_span_s``
    (s), ``initial_state_degree``, ``n_substeps``, ``null_pair_components``,
    ``min_null_pairs``, ``interval_scatter`` (whose scatter the fit's
    intervals take, hence their t quantile) and the bounds (N·m/rad,
    N·m·s/rad) as the fit uses them; ``force_cutoff_hz`` and ``force_order``
    the load cell's low-pass; ``force_rate_hz`` the rate of the pulse given
    to the fit (the robot log's).
    """

    pulse_force_n: float = 40.0
    pulse_duration_s: float = 0.1
    window_before_s: float = 0.025
    window_after_s: float = 0.25
    initial_state_span_s: float = 0.1
    initial_state_degree: int = 1
    n_substeps: int = 2
    null_pair_components: int = 6
    min_null_pairs: int = 30
    interval_scatter: str = "cross_validated_null_pairs"
    stiffness_bounds_nm_per_rad: tuple[float, float] = (0.0, 200.0)
    damping_bounds_nms_per_rad: tuple[float, float] = (0.0, 10.0)
    force_cutoff_hz: float = 40.0
    force_order: int = 4
    force_rate_hz: float = 1000.0

    def __post_init__(self):
        number("pulse_force_n", self.pulse_force_n)
        check_interval_scatter(self.interval_scatter)
        if number("force_rate_hz", self.force_rate_hz) <= 0:
            raise LoperInputError(f"force_rate_hz must be > 0 Hz, got {self.force_rate_hz:g}")
        d = number("pulse_duration_s", self.pulse_duration_s)
        after = number("window_after_s", self.window_after_s, minimum=0.0)
        if d <= 0:
            raise LoperInputError(f"pulse_duration_s must be > 0 s, got {d:g} s")
        if d > after:
            raise LoperInputError(
                f"pulse_duration_s = {d:g} s is longer than the fit window after the onset "
                f"(identification.window_after_s = {after:g} s): the fit would not see its end"
            )


@dataclass
class StrideCovariance:
    """The covariance (6, 6) of the estimate for one averaged perturbed stride (order :data:`PARAMETERS`).

    ``impedance`` (6,) the planned values it was linearised at; ``dof`` the
    degrees of freedom of the CI's Student t as the fit takes them: None for
    ``N - 1`` (the fit's intervals from the scatter of its ``N`` perturbed
    pairs), else a fixed count (the null pairs' ``M - 1``); ``n_null_pairs``
    and ``n_perturbed_pairs`` the pilot's pairs; ``scatter`` whose errors
    gave the covariance (``perturbed_pairs``, ``null_pairs`` or
    ``cross_validated_null_pairs``); ``note`` a caveat for the rows (empty
    when none). ``spread_covariance`` (6, 6): a part that falls as ``1/N^2``
    (the conditional counterfactual: the spread of the perturbed strides'
    prediction weights over candidates whose number grows with ``N``); for
    ``N`` strides the covariance is ``covariance / N + spread_covariance / N^2``.
    """

    covariance: np.ndarray
    impedance: np.ndarray
    dof: int | None
    n_null_pairs: int
    note: str = ""
    n_perturbed_pairs: int = 0
    scatter: str = "null_pairs"
    null_covariance: np.ndarray | None = None
    spread_covariance: np.ndarray | None = None

    @property
    def sd(self) -> np.ndarray:
        """SD (6,) of K and D for one stride (N·m/rad, N·m·s/rad), the ``1/N`` part."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def variance_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """``(a, b)`` variances (6,): for ``N`` strides the variance is ``a / N + b / N^2``."""
        spread = np.zeros(6) if self.spread_covariance is None else np.diag(self.spread_covariance)
        return np.clip(np.diag(self.covariance), 0.0, None), np.clip(spread, 0.0, None)

    def sd_of(self, n_strides: int) -> np.ndarray:
        """Predicted SD (6,) of K and D for ``n_strides`` averaged strides (N·m/rad, N·m·s/rad)."""
        a, b = self.variance_terms()
        n = int(n_strides)
        return np.sqrt(a / n + b / n**2)

    def t95(self, n_strides: int) -> float:
        """Student's t at 97.5 % the fit of ``n_strides`` averaged strides uses (inf when it has no dof;
        :func:`~loper_analysis.identification.t_quantile`, the fit's own)."""
        dof = int(n_strides) - 1 if self.dof is None else int(self.dof)
        return t_quantile(dof) if dof >= 1 else math.inf

    def half_width(self, n_strides: int) -> np.ndarray:
        """Predicted 95 % CI half-width (6,) for ``n_strides`` averaged strides (N·m/rad, N·m·s/rad)."""
        return self.t95(n_strides) * self.sd_of(n_strides)


def _null_arrays(null_pairs: Mapping, source: str) -> tuple[np.ndarray, dict[str, np.ndarray], int]:
    """Checked grid and arrays of the pilot's null pairs, and how many there are."""
    missing = [
        k
        for k in (
            "time_s",
            "q_perturbed",
            "q_unperturbed",
            "pelvis_angle_perturbed_rad",
            "pelvis_angle_unperturbed_rad",
        )
        if k not in null_pairs
    ]
    if missing:
        raise LoperInputError(f"{source}: null pairs lack {missing}")
    t = np.asarray(null_pairs["time_s"], dtype=float)
    arrays = {
        k: np.asarray(null_pairs[k], dtype=float)
        for k in ("q_perturbed", "q_unperturbed", "pelvis_angle_perturbed_rad", "pelvis_angle_unperturbed_rad")
    }
    n = int(arrays["q_unperturbed"].shape[0]) if arrays["q_unperturbed"].ndim == 3 else 0
    return t, arrays, n


def planning_window(
    null_pairs: Mapping,
    params: SegmentParameters,
    settings: PlanSettings = PlanSettings(),
    device=None,
    source: str = "pilot",
) -> PreparedWindow:
    """The identification window of the planned experiment (onset at t = 0).

    Reference: the mean of the pilot's unperturbed null-pair strides
    (``null_pairs["q_unperturbed"]`` (M, n, 4) and
    ``pelvis_angle_unperturbed_rad`` (M, n), on the grid ``time_s`` (n,)
    relative to the onset; :func:`loper_analysis.responses.null_pair_windows`),
    the mean swing a perturbed stride starts from. The perturbed force is
    :func:`pulse_force_n` along the thigh's forward normal of that swing,
    given to the fit at ``settings.force_rate_hz`` (``force_time_s`` of
    :func:`~loper_analysis.identification.prepare_window`, as the fit takes
    the robot log's samples); the minimal-impedance force and the initial
    deviation are zero (they average out over the perturbed strides).
    ``measured`` is zero: only the model's sensitivities are used.
    """
    from loper_analysis.synthetic.response import thigh_normal

    t, arrays, n_pairs = _null_arrays(null_pairs, source)
    if n_pairs < 1:
        raise LoperInputError(f"{source}: no null pairs: the pilot needs unperturbed strides walked with the device")
    q_ref = arrays["q_unperturbed"].mean(axis=0)
    pelvis = arrays["pelvis_angle_unperturbed_rad"].mean(axis=0)
    rate = float(settings.force_rate_hz)
    t_force = np.arange(math.ceil(t[0] * rate - 1e-6), math.floor(t[-1] * rate + 1e-6) + 1) / rate
    force = pulse_force_n(
        t_force,
        settings.pulse_force_n,
        settings.pulse_duration_s,
        device,
        settings.force_cutoff_hz,
        settings.force_order,
    )
    force_vector = force[:, None] * thigh_normal(np.interp(t_force, t, q_ref[:, 1]))
    return prepare_window(
        t,
        q_ref,
        q_ref,
        params,
        0.0,
        force_perturbed_n=force_vector,
        force_unperturbed_n=np.zeros_like(force_vector),
        force_time_s=t_force,
        pelvis_angle_unperturbed_rad=pelvis,
        pelvis_angle_perturbed_rad=pelvis,
        **window_options(settings),
    )


def _impedance(impedance, settings: PlanSettings, source: str) -> np.ndarray:
    p = np.asarray(impedance, dtype=float)
    if p.shape != (6,) or not np.all(np.isfinite(p)):
        raise LoperInputError(
            f"{source}: the planned impedance must be 6 finite values ({', '.join(PARAMETERS)}), "
            f"got {np.asarray(impedance).tolist()}"
        )
    out = np.flatnonzero((p < settings.lower) | (p > settings.upper))
    if out.size:
        i = int(out[0])
        raise LoperInputError(
            f"{source}: planned {PARAMETERS[i]} = {p[i]:g} {PARAMETER_UNITS[PARAMETERS[i]]} lies "
            f"outside the identification bounds {settings.lower[i]:g} .. {settings.upper[i]:g}"
        )
    return p


def stride_covariance(
    null_pairs: Mapping,
    params: SegmentParameters,
    impedance,
    settings: PlanSettings = PlanSettings(),
    device=None,
    source: str = "pilot",
    perturbed_pairs: Mapping | None = None,
) -> StrideCovariance:
    """Covariance of (K, D) per joint for a mean response of **one** perturbed stride.

    ``impedance`` (6,): the planned values (order :data:`PARAMETERS`; N·m/rad
    and N·m·s/rad), e.g. the pilot's estimate. With the window of
    :func:`planning_window`, ``J`` = :func:`~loper_analysis.identification.response_jacobian`
    at ``impedance``, the null-pair errors ``E0`` =
    :func:`~loper_analysis.identification.null_pair_errors`, ``W`` =
    :func:`~loper_analysis.identification.nuisance_projection` of ``E0``
    (``settings.null_pair_components`` shapes) and ``M = (W J)^+ W``:
    ``cov_1 = M cov(E) M^T``. For ``N`` strides the covariance is ``cov_1 / N``.

    ``E`` are the prediction errors of the pilot's ``perturbed_pairs`` (the
    kept perturbed-minus-matched pairs at this onset one by one, format of
    ``null_pairs``: ``series["pairs"]`` of
    :func:`loper_analysis.responses.subject_onset_response`): their scatter
    holds the stride-to-stride deviation *and* each stride's own answer to
    the pulse, the scatter the fit's intervals take
    (``identification.interval_scatter: perturbed_pairs``). Without them, or
    with fewer than :data:`MIN_PERTURBED_PAIRS`, ``E = E0`` and the note says
    the prediction lacks the response's variability. The t quantile is the
    fit's: ``N - 1`` degrees of freedom with ``interval_scatter``
    ``perturbed_pairs``, else the null pairs' ``M - 1``.

    Raises
    ------
    LoperInputError
        No null pairs, fewer than ``null_pair_components + 2`` of them (the
        projection cannot be estimated), a planned value outside the bounds.
    """
    p = _impedance(impedance, settings, source)
    _, _, n_pairs = _null_arrays(null_pairs, source)
    r = integer("null_pair_components", settings.null_pair_components, source, minimum=0)
    need = r + 2
    if n_pairs < need:
        raise LoperInputError(
            f"{source}: {n_pairs} null pair(s), fewer than identification.null_pair_components + 2 = {need}: "
            "the pilot needs unperturbed strides walked with the device (their deviation is what the prediction "
            "scales)"
        )
    notes = []
    if n_pairs < settings.min_null_pairs:
        notes.append(
            f"{n_pairs} null pairs, fewer than identification.min_null_pairs = {settings.min_null_pairs}: "
            "the pilot's own fits kept the white-noise fit; the prediction is that of a null-pair fit"
        )
    window = planning_window(null_pairs, params, settings, device, source)
    J = response_jacobian(window, p, settings.lower, settings.upper)
    E0 = null_pair_errors(window, p, null_pairs)
    W = nuisance_projection(E0, r)
    WJ = W @ J
    M = np.linalg.pinv(WJ.T @ WJ, rcond=1e-13) @ WJ.T @ W
    n_pert = 0
    if perturbed_pairs is not None:
        _, _, n_pert = _null_arrays(perturbed_pairs, f"{source}, perturbed pairs")
    if n_pert >= MIN_PERTURBED_PAIRS:
        E, scatter = null_pair_errors(window, p, perturbed_pairs), "perturbed_pairs"
    else:
        E, scatter = E0, "null_pairs"
        notes.append(
            (
                f"{n_pert} perturbed pair(s) of the pilot at this onset, fewer than {MIN_PERTURBED_PAIRS}"
                if perturbed_pairs is not None
                else "no perturbed pairs of the pilot at this onset"
            )
            + ": the null pairs' scatter, without each stride's own answer to the pulse (in the "
            "synthetic check the actual SD of hip and knee K and D was 1.4-1.8 times this prediction)"
        )

    def sandwich(errors: np.ndarray) -> np.ndarray:
        effect = (errors - errors.mean(axis=0)) @ M.T  # each pair's effect on (K, D)
        return effect.T @ effect / max(errors.shape[0] - 1, 1)

    dof = None if settings.interval_scatter == "perturbed_pairs" else n_pairs - 1
    return StrideCovariance(sandwich(E), p, dof, n_pairs, "; ".join(notes), n_pert, scatter, sandwich(E0))


def conditional_stride_covariance(
    series: Mapping,
    params: SegmentParameters,
    impedance,
    settings: PlanSettings = PlanSettings(),
    device=None,
    source: str = "pilot",
) -> StrideCovariance:
    """Covariance of (K, D) per joint for the conditional counterfactual, as the fit's intervals take it.

    ``series``: the pilot's onset series with the conditional counterfactual
    (:func:`loper_analysis.planning.inputs.pilot_onset_series`): ``null_pairs``,
    each unperturbed candidate against its prediction from the others (with
    ``unit_scatter_variance``), and ``pairs``, its perturbed pairs (with their
    ``prediction_weights`` over the candidates). With the window of
    :func:`planning_window`, the errors ``E0`` of the null pairs, ``J`` at
    ``impedance`` and ``V`` = :func:`~loper_analysis.identification.cross_validated_covariance`
    of ``E0`` for one stride, white stride noise of variance ``s^2`` gives
    ``V = s^2 v`` (``v`` the unit scatter variance), and the mean of ``N``
    predicted pairs has ``s^2 (1 / N + |mu|^2 + tr Sigma / N)``
    (:func:`loper_analysis.responses.conditional.shared_weight_terms` of the
    pilot's ``P`` perturbed pairs' weights over its candidates). The planned
    experiment perturbs at the pilot's rate, so its candidates grow with
    ``N`` and both weight terms, about inversely proportional to the
    candidates, scale by ``P / N``: ``covariance = V (1 + P |mu|^2) / v``
    per stride and ``spread_covariance = V P tr Sigma / v``. At ``N = P``
    this is the pilot fit's own interval (``cross_validated_null_pairs``, t
    with ``M - 1`` degrees of freedom).

    Raises
    ------
    LoperInputError
        Fewer than ``null_pair_components + 3`` null pairs, no perturbed pair
        (their weights say how much of the candidates' noise the mean keeps),
        a planned value outside the bounds.
    """
    from loper_analysis.responses.conditional import shared_weight_terms

    p = _impedance(impedance, settings, source)
    null = series.get("null_pairs") or {}
    n_null = int(null.get("n_pairs", 0))
    r = integer("null_pair_components", settings.null_pair_components, source, minimum=0)
    if n_null < r + 3 or "unit_scatter_variance" not in null:
        raise LoperInputError(
            f"{source}: {n_null} unperturbed stride(s) predicted from the others at this onset, fewer than "
            f"identification.null_pair_components + 3 = {r + 3}: the conditional counterfactual's intervals "
            "need the onset's own unperturbed strides"
        )
    pairs = series.get("pairs") or {}
    n_pert = int(pairs.get("n_pairs", 0))
    if n_pert < 1 or "prediction_weights" not in pairs:
        raise LoperInputError(
            f"{source}: no perturbed stride of the pilot at this onset: the conditional counterfactual's plan "
            "needs the pilot's perturbed strides (their prediction weights); plan with "
            "identification.counterfactual: matched_stride instead"
        )
    notes = []
    if n_null < settings.min_null_pairs:
        notes.append(
            f"{n_null} null pairs, fewer than identification.min_null_pairs = {settings.min_null_pairs}: "
            "the pilot's own fits fell back to the matched stride"
        )
    window = planning_window(null, params, settings, device, source)
    J = response_jacobian(window, p, settings.lower, settings.upper)
    V = cross_validated_covariance(null_pair_errors(window, p, null), r, J, 1)
    unit = float(null["unit_scatter_variance"])
    mu2, spread = shared_weight_terms(pairs["prediction_weights"])
    return StrideCovariance(
        V * (1.0 + n_pert * mu2) / unit,
        p,
        n_null - 1,
        n_null,
        "; ".join(notes),
        n_pert,
        "cross_validated_null_pairs",
        None,
        V * n_pert * spread / unit,
    )


def stretch_covariances(
    trials: Sequence[Mapping],
    onset_ms: float,
    n_strides: Sequence[int],
    params: SegmentParameters,
    impedance,
    settings: PlanSettings = PlanSettings(),
    device=None,
    response=None,
    source: str = "pilot",
    min_stretches: int = 2,
) -> dict[int, StrideCovariance]:
    """``{N: covariance}`` for the conditional counterfactual from stretches of the pilot holding ``N`` strides.

    A planned experiment of ``N`` perturbed strides is shorter than the
    pilot, so it has fewer unperturbed candidates, and the fit's interval
    depends on them not only through their number (the nuisance projection
    and the ridge's penalty are estimated from them too). For every ``N``
    the pilot's trials at ``onset_ms`` hold at least ``min_stretches`` times
    (:func:`~loper_analysis.planning.inputs.trial_stretches`), each stretch
    is planned alone (:func:`conditional_stride_covariance` of its own series
    at ``impedance``) and the covariance is the mean over the stretches of
    both its parts (``covariance`` and ``spread_covariance``): what the fit
    of an ``N``-stride experiment reports, averaged over the pilot's
    experiments of that size. Counts held fewer times are left out (plan them
    with the whole pilot); a stretch that cannot be planned (too few
    candidates or no perturbed stride kept) is skipped. ``response``: the
    response settings (default :class:`~loper_analysis.responses.ResponseSettings`,
    whose counterfactual must be ``conditional``).
    """
    from loper_analysis.responses import ResponseSettings

    response = ResponseSettings() if response is None else response
    if response.counterfactual != "conditional":
        raise LoperInputError(
            f"{source}: stretches of the pilot are planned for the conditional counterfactual, "
            f"not {response.counterfactual!r}"
        )
    out = {}
    for n in _counts(n_strides, source):
        covs = []
        for trial in trials:
            for stretch in trial_stretches(trial, n):
                series = pilot_onset_series([stretch], onset_ms, response, source=stretch["name"])
                if series is None:
                    continue
                try:
                    covs.append(conditional_stride_covariance(series, params, impedance, settings, device, source))
                except LoperInputError:
                    continue
        if len(covs) >= max(int(min_stretches), 1):
            out[n] = _mean_covariance(covs, n, settings.min_null_pairs)
    return out


def _mean_covariance(covs: Sequence[StrideCovariance], n: int, min_null_pairs: int) -> StrideCovariance:
    spread = [c.spread_covariance if c.spread_covariance is not None else np.zeros((6, 6)) for c in covs]
    notes = [f"mean over {len(covs)} stretches of the pilot holding {n} perturbed strides each"]
    few = sum(c.n_null_pairs < min_null_pairs for c in covs)
    if few:
        notes.append(
            f"{few} of them with fewer than identification.min_null_pairs = {min_null_pairs} null pairs: "
            "a fit of that size would fall back to the matched stride"
        )
    return StrideCovariance(
        np.mean([c.covariance for c in covs], axis=0),
        covs[0].impedance,
        min(c.dof for c in covs) if all(c.dof is not None for c in covs) else None,
        int(round(np.mean([c.n_null_pairs for c in covs]))),
        "; ".join(notes),
        int(round(np.mean([c.n_perturbed_pairs for c in covs]))),
        covs[0].scatter,
        None,
        np.mean(spread, axis=0),
    )


def pool_onsets(stride_covs: Mapping[float, StrideCovariance]) -> dict[float, StrideCovariance]:
    """The perturbed pairs' excess scatter pooled over the pilot's onsets (``{onset_ms: StrideCovariance}``).

    Per onset ``o`` with the scatter of ``P_o`` perturbed pairs, the ratio
    ``r_o = diag(cov) / diag(null_covariance)`` (6,) says how much more the
    perturbed pairs scatter than the null pairs for each K and D. The pooled
    ratio ``r = sum (P_o - 1) r_o / sum (P_o - 1)`` is applied to every
    onset's null-pair sandwich, which rests on 100+ pairs:
    ``cov_o = diag(sqrt r) null_covariance_o diag(sqrt r)`` (``scatter``
    ``pooled_perturbed_pairs``), onsets without perturbed pairs included. A
    dozen pairs per onset (the default design) leave each ``r_o`` uncertain
    by about +-45 % (95 %); pooled over three onsets, +-25 %. With fewer than
    two onsets with perturbed pairs the covariances are returned unchanged.
    """
    own = {o: sc for o, sc in stride_covs.items() if sc.scatter == "perturbed_pairs"}
    if len(own) < 2:
        return dict(stride_covs)
    weights = np.array([sc.n_perturbed_pairs - 1 for sc in own.values()], float)
    ratios = np.array([np.diag(sc.covariance) / np.diag(sc.null_covariance) for sc in own.values()])
    r = weights @ ratios / weights.sum()
    scale = np.sqrt(r)
    pooled_note = (
        f"perturbed/null pairs' variance ratio pooled over onsets {', '.join(f'{o:g}' for o in own)} ms "
        f"({int(sum(sc.n_perturbed_pairs for sc in own.values()))} perturbed pairs)"
    )
    out = {}
    for o, sc in stride_covs.items():
        notes = [n for n in sc.note.split("; ") if n and "perturbed pair" not in n] + [pooled_note]
        out[o] = StrideCovariance(
            scale[:, None] * sc.null_covariance * scale[None, :],
            sc.impedance,
            sc.dof,
            sc.n_null_pairs,
            "; ".join(notes),
            sc.n_perturbed_pairs,
            "pooled_perturbed_pairs",
            sc.null_covariance,
        )
    return out


def _counts(n_strides: Sequence[int], source: str) -> list[int]:
    values = list(np.atleast_1d(n_strides)) if not isinstance(n_strides, (int, np.integer)) else [n_strides]
    if not values:
        raise LoperInputError(f"{source}: no stride count given")
    out = []
    for v in values:
        try:
            ok = float(v) == int(v)
        except (TypeError, ValueError):
            ok = False
        if not ok or int(v) < 1:
            raise LoperInputError(
                f"{source}: stride count must be a whole number >= 1 (perturbed strides averaged), got {v!r}"
            )
        out.append(int(v))
    return out


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
    counts = _counts(n_strides, subject or "plan")
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
    counts = _counts(n_strides, subject or "plan")
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
