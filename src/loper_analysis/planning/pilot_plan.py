"""A pilot subject's plan: the predicted precision of K and D at every onset and stride count, and the answers
to the targets, from the pilot's tables (method: ``docs/planning.md``).

:class:`PlanningSettings` holds what the planner follows (built from the config by
:mod:`loper_analysis.stages.planning.settings`, for the rule ``planning`` and ``loper-analysis plan`` alike);
:func:`pilot_plan` runs the onsets, pools the perturbed pairs' excess scatter over them and words the answers.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses import MAX_TRIAL_DEVIATION_RATIO, ResponseSettings, null_pair_windows
from loper_analysis.planning.covariance import (
    conditional_stride_covariance,
    pool_onsets,
    stretch_covariances,
    stride_covariance,
)
from loper_analysis.planning.inputs import pilot_onset_series, pilot_perturbed_pairs
from loper_analysis.planning.precision import precision_table, target_answer, unplanned_rows
from loper_analysis.planning.window import PlanSettings
from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = ["STRIDES", "PlanningSettings", "check_plan_request", "pilot_plan", "planned_impedance"]

log = logging.getLogger(__name__)

#: Counts of perturbed strides averaged that the planner predicts for (config ``planning.strides``).
STRIDES: tuple[int, ...] = (10, 20, 40)


@dataclass(frozen=True)
class PlanningSettings:
    """The planner's settings: onsets, stride counts, targets, the planned pulse and what the fit would do.

    Attributes
    ----------
    onsets_ms : tuple of float, or None
        Onsets after toe-off (ms) to plan for; None: not set (``loper-analysis plan`` takes those of the
        pilot's impedance rows; :func:`plan` needs them).
    strides : tuple of int
        Counts of perturbed strides averaged to predict for.
    targets : tuple of mapping
        Each ``joint``, ``parameter`` (``K``/``D``), ``percent`` or ``half_width`` (N·m/rad, N·m·s/rad) and
        optionally ``onset_ms`` (else every onset).
    plan : PlanSettings
        The planned pulse (N, s) and the identification settings the prediction follows
        (:class:`~loper_analysis.planning.window.PlanSettings`).
    response : ResponseSettings
        How the pilot's pairs are windowed and judged (:class:`~loper_analysis.impedance.responses.ResponseSettings`),
        and the counterfactual planned for: ``conditional`` (the default) takes the fit's cross-validated null
        pairs, ``matched_stride`` the scatter of the pilot's perturbed pairs
        (:func:`~loper_analysis.planning.covariance.conditional_stride_covariance`).
    device : DeviceParameters
        The device (:class:`~loper_analysis.device.controller.DeviceParameters`).
    max_null_trial_ratio : float or None
        A pilot trial whose null pairs deviate more than this multiple of the other trials' is left out of
        the null pairs (None: never).
    pilot_subject : str or None
        The subject whose recordings the planner takes as the pilot (None: the study's first processed subject).
    """

    onsets_ms: tuple[float, ...] | None = None
    strides: tuple[int, ...] = STRIDES
    targets: tuple[Mapping, ...] = ()
    plan: PlanSettings = field(default_factory=PlanSettings)
    response: ResponseSettings = field(default_factory=ResponseSettings)
    device: DeviceParameters = field(default_factory=DeviceParameters)
    max_null_trial_ratio: float | None = MAX_TRIAL_DEVIATION_RATIO
    pilot_subject: str | None = None


def planned_impedance(table: pd.DataFrame, subject: str, onset_ms: int, source: str) -> np.ndarray:
    """K, D per joint (6,) of ``subject`` at ``onset_ms`` from impedance rows (``results/impedance/...``).

    Raises a :class:`LoperInputError` naming ``source`` when the subject has no
    row with an estimate of every joint at that onset (e.g. a ``failed`` fit).
    """
    need = ["subject", "onset_ms", "joint", parameter_column("K"), parameter_column("D")]
    missing = [c for c in need if c not in table.columns]
    if missing:
        raise LoperInputError(f"{source}: impedance rows lack column(s) {missing}")
    rows = table[(table["subject"].astype(str) == str(subject)) & (table["onset_ms"].astype(float) == float(onset_ms))]
    values = []
    for joint in JOINTS:
        row = rows[rows["joint"] == joint]
        k = row[parameter_column("K")].to_numpy(float)
        d = row[parameter_column("D")].to_numpy(float)
        if len(row) != 1 or not (np.isfinite(k).all() and np.isfinite(d).all()):
            status = ", ".join(f"{s}: {r}" for s, r in zip(row.get("status", []), row.get("reason", []))) or "no row"
            raise LoperInputError(
                f"{source}: no fitted impedance of subject {subject} at onset {onset_ms:g} ms "
                f"for the {joint} ({status}); give the planned impedance explicitly"
            )
        values += [float(k[0]), float(d[0])]
    return np.array(values)


def check_plan_request(settings: PlanningSettings, unplannable: str = "raise") -> list[int]:
    """The stride counts to plan for, checked with the onsets and ``unplannable`` before any work.

    Raises
    ------
    LoperInputError
        ``unplannable`` neither ``raise`` nor ``note``, no onsets, a count that is not a whole number >= 1.
    """
    if unplannable not in ("raise", "note"):
        raise LoperInputError(f"unplannable must be 'raise' or 'note', got {unplannable!r}")
    if settings.onsets_ms is None:
        raise LoperInputError("planning settings: no onsets (onsets_ms) to plan for")
    counts = list(settings.strides)
    for n in counts:
        if isinstance(n, bool) or not float(n) == int(n) or int(n) < 1:
            raise LoperInputError(f"stride count must be a whole number >= 1 (perturbed strides averaged), got {n!r}")
    return counts


def pilot_plan(
    pool: list[dict],
    params: SegmentParameters,
    settings: PlanningSettings,
    subject: str,
    *,
    impedance_rows: pd.DataFrame | None = None,
    impedance: Mapping[int, Sequence[float]] | Sequence[float] | None = None,
    source: str = "",
    unplannable: str = "raise",
    pool_scatter: bool = True,
) -> tuple[pd.DataFrame, list[str]]:
    """Predicted SD and 95 % CI half-width of K and D for a planned experiment, and the answers to the targets.

    Parameters
    ----------
    pool : list of dict
        The pilot's trials with the device: ``name``, ``angles`` and ``strides`` tables.
    params : SegmentParameters
        The swing leg of the subject planned for.
    settings : PlanningSettings
        Onsets (ms), stride counts, targets, pulse, identification, response and device settings.
    subject : str
        The pilot's ID (rows of ``impedance_rows``, messages).
    impedance_rows, impedance
        The planned impedance: the pilot's fit rows (read from ``source``), or the values (6, order of
        ``PARAMETERS``), one set for every onset or ``{onset_ms: values}``.
    unplannable : {"raise", "note"}
        An onset whose pilot fit has no estimate or whose null pairs are too few: stop, or write its rows
        without a prediction with the cause in ``note``.
    pool_scatter : bool
        Pool the perturbed pairs' excess scatter over the onsets
        (:func:`loper_analysis.planning.covariance.pool_onsets`); False: each onset its own.

    Returns
    -------
    (pandas.DataFrame, list of str)
        The table (:data:`loper_analysis.planning.precision.PLAN_COLUMNS`) and the answers.
    """
    counts = check_plan_request(settings, unplannable)
    planned, failed, by_count = {}, {}, {}
    for onset in settings.onsets_ms:
        where = f"pilot {subject}, onset {onset:g} ms"
        try:
            if impedance is None:
                values = planned_impedance(impedance_rows, subject, onset, source)
            else:
                values = np.asarray(impedance[onset] if isinstance(impedance, Mapping) else impedance, float)
            planned[onset], by_count[onset] = _onset_covariance(
                pool, onset, counts, params, values, settings, subject, where
            )
        except LoperInputError as exc:
            if unplannable == "raise":
                raise
            log.warning("%s: not planned: %s", where, exc)
            failed[onset] = unplanned_rows(counts, onset, f"not planned: {exc}", subject, settings.plan)
    if pool_scatter:
        planned = pool_onsets(planned)
    tables, answers = [], []
    for onset in settings.onsets_ms:
        if onset in failed:
            tables.append(failed[onset])
            continue
        sc = planned[onset]
        tables.append(precision_table(sc, counts, onset, subject, settings.plan, by_count.get(onset)))
        log.info(
            "pilot %s, onset %g ms: %d null pairs, %d perturbed pairs (scatter: %s); planned %s",
            subject,
            onset,
            sc.n_null_pairs,
            sc.n_perturbed_pairs,
            sc.scatter.replace("_", " "),
            ", ".join(f"{p} {v:.3g}" for p, v in zip(sc.parameters, sc.impedance)),
        )
        answers += _answers(sc, onset, settings.targets) + coupling_answers(tables[-1], onset, settings.plan)
    return pd.concat(tables, ignore_index=True), answers


def coupling_answers(table: pd.DataFrame, onset: float, plan: PlanSettings) -> list[str]:
    """Whether the design identifies each planned coupling at ``onset`` (ms): one sentence per coupling of
    ``plan.couplings`` from its rows of the precision ``table`` (its largest stride count), naming the keys that
    set the design (``impedance.couplings``, ``planning.shank_pulse_force_n``)."""
    out = []
    rods = f"planning.shank_pulse_force_n = {plan.shank_pulse_force_n:g} N"
    for coupling in plan.couplings:
        rows = table[table["joint"] == coupling]
        if rows.empty:
            continue
        row = rows.loc[rows["n_strides"].idxmax()]
        needed = row["strides_to_identify"]
        more = f"needs {needed:.0f} perturbed strides" if np.isfinite(needed) else "needs more strides than planned"
        out.append(
            f"K_{coupling} at {onset:g} ms (impedance.couplings; {rods}): {row['verdict']} at {row['n_strides']:.0f} "
            f"strides (95 % half-width ±{row['ci95_half_width']:.3g} N·m/rad against the tolerance "
            f"{row['tolerance']:.3g}); {more} to be identified"
        )
    return out


def _onset_covariance(pool, onset, counts, params, values, settings: PlanningSettings, subject: str, where: str):
    """One onset's planned covariance, and with the conditional counterfactual that of each stride count the
    pilot holds in stretches (None otherwise)."""
    response, plan, dev = settings.response, settings.plan, settings.device
    if response.counterfactual == "conditional":
        series = pilot_onset_series(pool, onset, response, source=subject)
        if series is None:
            raise LoperInputError(
                f"{where}: no trial of the pilot is perturbed at this onset: the conditional "
                "counterfactual's plan takes the onset's own strides (or plan with "
                "impedance.counterfactual: matched_stride)"
            )
        planned = conditional_stride_covariance(series, params, values, plan, dev, source=where)
        return planned, stretch_covariances(
            pool, onset, counts, params, values, settings=plan, device=dev, response=response, source=where
        )
    null = null_pair_windows(pool, onset, response, source=subject, max_trial_ratio=settings.max_null_trial_ratio)
    pairs = pilot_perturbed_pairs(pool, onset, response, source=subject)
    return stride_covariance(null, params, values, plan, dev, source=where, perturbed_pairs=pairs), None


def _answers(sc, onset: float, targets: Sequence[Mapping]) -> list[str]:
    """The answers to the targets at one onset (those without an onset, and those of this one)."""
    return [
        target_answer(
            sc,
            str(target["joint"]),
            str(target["parameter"]),
            onset,
            percent=target.get("percent"),
            half_width=target.get("half_width"),
        )
        for target in targets
        if target.get("onset_ms") is None or float(target["onset_ms"]) == float(onset)
    ]
