"""The covariance of (K, D) per joint for one perturbed stride, as the fit would estimate it (method:
``docs/planning.md``).

* :func:`stride_covariance` - from the pilot's perturbed pairs (or its null pairs when it has none at the
  onset), for the study's matched stride;
* :func:`conditional_stride_covariance` - the same for the conditional counterfactual, from the pilot's
  cross-validated null pairs as the fit's intervals take them;
* :func:`stretch_covariances` - for stride counts the pilot holds several times over: the mean over the
  pilot's stretches of the planned size;
* :func:`pool_onsets` - the perturbed pairs' excess scatter pooled over the pilot's onsets.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import integer
from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    cross_validated_covariance,
    nuisance_projection,
    null_pair_errors,
    response_jacobian,
    t_quantile,
)
from loper_analysis.planning.inputs import pilot_onset_series, trial_stretches
from loper_analysis.planning.window import PlanSettings, null_pair_arrays, planned_impedance, planning_window
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = [
    "stride_counts",
    "MIN_PERTURBED_PAIRS",
    "StrideCovariance",
    "conditional_stride_covariance",
    "pool_onsets",
    "stretch_covariances",
    "stride_covariance",
]


#: Fewest pilot perturbed pairs whose scatter the prediction takes (fewer: the null pairs' scatter, noted).
MIN_PERTURBED_PAIRS = 5


@dataclass
class StrideCovariance:
    """The covariance (p, p) of the estimate for one averaged perturbed stride (order :attr:`parameters`:
    :data:`PARAMETERS`, then ``K_<coupling>`` for each of ``couplings``, the inter-joint stiffnesses planned).

    ``impedance`` (p,) the planned values it was linearised at; ``dof`` the
    degrees of freedom of the CI's Student t as the fit takes them: None for
    ``N - 1`` (the fit's intervals from the scatter of its ``N`` perturbed
    pairs), else a fixed count (the null pairs' ``M - 1``); ``n_null_pairs``
    and ``n_perturbed_pairs`` the pilot's pairs; ``scatter`` whose errors
    gave the covariance (``perturbed_pairs``, ``null_pairs`` or
    ``cross_validated_null_pairs``); ``note`` a caveat for the rows (empty
    when none). ``spread_covariance`` (p, p): a part that falls as ``1/N^2``
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
    couplings: tuple[str, ...] = ()

    @property
    def parameters(self) -> tuple[str, ...]:
        """Names of the covariance's rows: :data:`PARAMETERS`, then ``K_<coupling>`` per coupling."""
        return PARAMETERS + tuple(f"K_{c}" for c in self.couplings)

    @property
    def sd(self) -> np.ndarray:
        """SD (p,) of K and D (and the couplings) for one stride (N·m/rad, N·m·s/rad), the ``1/N`` part."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def variance_terms(self) -> tuple[np.ndarray, np.ndarray]:
        """``(a, b)`` variances (p,): for ``N`` strides the variance is ``a / N + b / N^2``."""
        a = np.diag(self.covariance)
        spread = np.zeros(len(a)) if self.spread_covariance is None else np.diag(self.spread_covariance)
        return np.clip(a, 0.0, None), np.clip(spread, 0.0, None)

    def sd_of(self, n_strides: int) -> np.ndarray:
        """Predicted SD (p,) of K and D (and the couplings) for ``n_strides`` averaged strides (N·m/rad,
        N·m·s/rad)."""
        a, b = self.variance_terms()
        n = int(n_strides)
        return np.sqrt(a / n + b / n**2)

    def t95(self, n_strides: int) -> float:
        """Student's t at 97.5 % the fit of ``n_strides`` averaged strides uses (inf when it has no dof;
        :func:`~loper_analysis.impedance.identification.t_quantile`, the fit's own)."""
        dof = int(n_strides) - 1 if self.dof is None else int(self.dof)
        return t_quantile(dof) if dof >= 1 else math.inf

    def half_width(self, n_strides: int) -> np.ndarray:
        """Predicted 95 % CI half-width (p,) for ``n_strides`` averaged strides (N·m/rad, N·m·s/rad)."""
        return self.t95(n_strides) * self.sd_of(n_strides)


def _pilot_rods(pairs: Mapping) -> int:
    """How many rods pushed the pilot's perturbed pairs: 2 when their forces hold a second rod's (4 columns)."""
    force = pairs.get("force_perturbed_n")
    return 2 if force is not None and np.shape(force)[-1] == 4 else 1


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
    and N·m·s/rad), e.g. the pilot's estimate; with ``settings.couplings`` also (6 + their number,) with the
    couplings' planned stiffness (N·m/rad) after them, else each coupling is planned at 0
    (:func:`~loper_analysis.planning.window.planned_impedance`). With the window of
    :func:`planning_window`, ``J`` = :func:`~loper_analysis.impedance.identification.response_jacobian`
    at ``impedance``, the null-pair errors ``E0`` =
    :func:`~loper_analysis.impedance.identification.null_pair_errors`, ``W`` =
    :func:`~loper_analysis.impedance.identification.nuisance_projection` of ``E0``
    (``settings.null_pair_components`` shapes) and ``M = (W J)^+ W``:
    ``cov_1 = M cov(E) M^T``. For ``N`` strides the covariance is ``cov_1 / N``.

    ``E`` are the prediction errors of the pilot's ``perturbed_pairs`` (the
    kept perturbed-minus-matched pairs at this onset one by one, format of
    ``null_pairs``: ``series["pairs"]`` of
    :func:`loper_analysis.impedance.responses.subject_onset_response`): their scatter
    holds the stride-to-stride deviation *and* each stride's own answer to
    the pulse, the scatter the fit's intervals take
    (``impedance.interval_scatter: perturbed_pairs``). Without them, or
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
    p = planned_impedance(impedance, settings, source)
    _, _, n_pairs = null_pair_arrays(null_pairs, source)
    r = integer("null_pair_components", settings.null_pair_components, source, minimum=0)
    need = r + 2
    if n_pairs < need:
        raise LoperInputError(
            f"{source}: {n_pairs} null pair(s), fewer than impedance.null_pair_components + 2 = {need}: "
            "the pilot needs unperturbed strides walked with the device (their deviation is what the prediction "
            "scales)"
        )
    notes = []
    if n_pairs < settings.min_null_pairs:
        notes.append(
            f"{n_pairs} null pairs, fewer than impedance.min_null_pairs = {settings.min_null_pairs}: "
            "the pilot's own fits kept the white-noise fit; the prediction is that of a null-pair fit"
        )
    window = planning_window(null_pairs, params, settings, device, source)
    J = response_jacobian(window, p, settings.lower, settings.upper)
    E0 = null_pair_errors(window, p, null_pairs)
    W = nuisance_projection(E0, r)
    WJ = W @ J
    M = np.linalg.pinv(WJ.T @ WJ, rcond=1e-13) @ WJ.T @ W
    n_pert = 0
    other_design = perturbed_pairs is not None and _pilot_rods(perturbed_pairs) != (
        2 if settings.shank_pulse_force_n else 1
    )
    if other_design:
        notes.append(
            f"the pilot's perturbed pairs were pushed by {_pilot_rods(perturbed_pairs)} rod(s), the plan by "
            f"{2 if settings.shank_pulse_force_n else 1}: they do not show that design's response; the null pairs' "
            "scatter taken"
        )
    elif perturbed_pairs is not None:
        _, _, n_pert = null_pair_arrays(perturbed_pairs, f"{source}, perturbed pairs")
    if n_pert >= MIN_PERTURBED_PAIRS:
        E, scatter = null_pair_errors(window, p, perturbed_pairs), "perturbed_pairs"
    else:
        E, scatter = E0, "null_pairs"
    if n_pert < MIN_PERTURBED_PAIRS and not other_design:
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
    return StrideCovariance(
        sandwich(E), p, dof, n_pairs, "; ".join(notes), n_pert, scatter, sandwich(E0), couplings=settings.couplings
    )


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
    ``impedance`` and ``V`` = :func:`~loper_analysis.impedance.identification.cross_validated_covariance`
    of ``E0`` for one stride, white stride noise of variance ``s^2`` gives
    ``V = s^2 v`` (``v`` the unit scatter variance), and the mean of ``N``
    predicted pairs has ``s^2 (1 / N + |mu|^2 + tr Sigma / N)``
    (:func:`loper_analysis.impedance.responses.conditional.shared_weight_terms` of the
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
    from loper_analysis.impedance.responses.conditional import shared_weight_terms

    p = planned_impedance(impedance, settings, source)
    null = series.get("null_pairs") or {}
    n_null = int(null.get("n_pairs", 0))
    r = integer("null_pair_components", settings.null_pair_components, source, minimum=0)
    if n_null < r + 3 or "unit_scatter_variance" not in null:
        raise LoperInputError(
            f"{source}: {n_null} unperturbed stride(s) predicted from the others at this onset, fewer than "
            f"impedance.null_pair_components + 3 = {r + 3}: the conditional counterfactual's intervals "
            "need the onset's own unperturbed strides"
        )
    pairs = series.get("pairs") or {}
    n_pert = int(pairs.get("n_pairs", 0))
    if n_pert < 1 or "prediction_weights" not in pairs:
        raise LoperInputError(
            f"{source}: no perturbed stride of the pilot at this onset: the conditional counterfactual's plan "
            "needs the pilot's perturbed strides (their prediction weights); plan with "
            "impedance.counterfactual: matched_stride instead"
        )
    notes = []
    if n_null < settings.min_null_pairs:
        notes.append(
            f"{n_null} null pairs, fewer than impedance.min_null_pairs = {settings.min_null_pairs}: "
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
        settings.couplings,
    )


def stretch_covariances(
    trials: Sequence[Mapping],
    onset_ms: float,
    n_strides: Sequence[int],
    params: SegmentParameters,
    impedance,
    *,
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
    response settings (default :class:`~loper_analysis.impedance.responses.ResponseSettings`,
    whose counterfactual must be ``conditional``).
    """
    from loper_analysis.impedance.responses import ResponseSettings

    response = ResponseSettings() if response is None else response
    if response.counterfactual != "conditional":
        raise LoperInputError(
            f"{source}: stretches of the pilot are planned for the conditional counterfactual, "
            f"not {response.counterfactual!r}"
        )
    out = {}
    for n in stride_counts(n_strides, source):
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
    spread = [c.spread_covariance if c.spread_covariance is not None else np.zeros_like(c.covariance) for c in covs]
    notes = [f"mean over {len(covs)} stretches of the pilot holding {n} perturbed strides each"]
    few = sum(c.n_null_pairs < min_null_pairs for c in covs)
    if few:
        notes.append(
            f"{few} of them with fewer than impedance.min_null_pairs = {min_null_pairs} null pairs: "
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
        covs[0].couplings,
    )


def pool_onsets(stride_covs: Mapping[float, StrideCovariance]) -> dict[float, StrideCovariance]:
    """The perturbed pairs' excess scatter pooled over the pilot's onsets (``{onset_ms: StrideCovariance}``).

    Per onset ``o`` with the scatter of ``P_o`` perturbed pairs, the ratio
    ``r_o = diag(cov) / diag(null_covariance)`` (p,) says how much more the
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
            couplings=sc.couplings,
        )
    return out


def stride_counts(n_strides: Sequence[int], source: str) -> list[int]:
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
