"""File step of the experiment planner: a pilot subject's tables in, the predicted precision table out.

:func:`plan` reads the pilot's joint-angle and stride tables (the trials with
the device, whose unperturbed strides give the null pairs and whose perturbed
strides at an onset give that onset's perturbed pairs), its segment table
(or another subject's) and its impedance rows (the planned impedance): a
:class:`PilotFiles` bundle. It writes the table of
:func:`loper_analysis.planning.precision.precision_table` for every onset and
the answers to the targets (method: ``docs/planning.md``; with the conditional
counterfactual, counts the pilot holds at least twice at an onset are planned
from its stretches of that size,
:func:`loper_analysis.planning.covariance.stretch_covariances`), with the settings
:class:`PlanningSettings`, which the rule ``planning`` and ``loper-analysis
plan`` both build with :meth:`PlanningSettings.from_config`.
"""

from __future__ import annotations

import copy
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, PARAMETERS, parameter_column
from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_text, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.planning.window import PlanSettings
from loper_analysis.responses import MAX_TRIAL_DEVIATION_RATIO, ResponseSettings

__all__ = ["STRIDES", "PlanningSettings", "PilotTrial", "PilotFiles", "plan", "planned_impedance"]

log = logging.getLogger(__name__)

#: Counts of perturbed strides averaged that the planner predicts for (config ``planning.strides``).
STRIDES: tuple[int, ...] = (10, 20, 40)

#: Identification settings the planner follows (keys of config ``identification``; fields of
#: :class:`~loper_analysis.planning.window.PlanSettings`).
_PLAN_KEYS = (
    "window_before_s",
    "window_after_s",
    "initial_state_span_s",
    "initial_state_degree",
    "n_substeps",
    "null_pair_components",
    "min_null_pairs",
    "interval_scatter",
    "stiffness_bounds_nm_per_rad",
    "damping_bounds_nms_per_rad",
)


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
        How the pilot's pairs are windowed and judged (:class:`~loper_analysis.responses.ResponseSettings`),
        and the counterfactual planned for: ``conditional`` (the default) takes the fit's cross-validated null
        pairs, ``matched_stride`` the scatter of the pilot's perturbed pairs
        (:func:`~loper_analysis.planning.covariance.conditional_stride_covariance`).
    device : DeviceParameters
        The device (:class:`~loper_analysis.device.controller.DeviceParameters`).
    max_null_trial_ratio : float or None
        A pilot trial whose null pairs deviate more than this multiple of the other trials' is left out of
        the null pairs (None: never).
    """

    onsets_ms: tuple[float, ...] | None = None
    strides: tuple[int, ...] = STRIDES
    targets: tuple[Mapping, ...] = ()
    plan: PlanSettings = field(default_factory=PlanSettings)
    response: ResponseSettings = field(default_factory=ResponseSettings)
    device: DeviceParameters = field(default_factory=DeviceParameters)
    max_null_trial_ratio: float | None = MAX_TRIAL_DEVIATION_RATIO

    @classmethod
    def from_config(cls, config: Mapping) -> PlanningSettings:
        """The planner's settings from the workflow's configuration: the rule ``planning`` and
        ``loper-analysis plan`` both take theirs from here, so that the two cannot drift apart.

        Parameters
        ----------
        config : mapping
            The validated configuration (``config/config.yaml`` and its layers;
            :func:`loper_analysis.config_file.load_config`). ``onsets_ms``: ``trials.perturbation_onsets_ms``;
            ``strides``, ``targets``: ``planning.strides``, ``planning.targets``; ``plan``: the pulse
            ``planning.pulse_force_n`` (N) and ``planning.pulse_duration_s`` (s) with the keys of
            ``identification`` the planner follows (fit window and initial state in s, substeps, projected
            components, null-pair minimum, interval scatter and the K, D bounds in N·m/rad, N·m·s/rad);
            ``response``: ``identification.window_before_s``, ``window_after_s``, ``initial_state_span_s``
            and ``strides.iqr_whisker``, ``strides.max_outlier_fraction``, the counterfactual planned for
            ``identification.counterfactual``; ``device``:
            ``device.parameters``; ``max_null_trial_ratio``: ``identification.max_null_trial_ratio``.

        Raises
        ------
        LoperInputError
            A key the planner needs is missing (naming it), or the settings cannot serve (e.g. a pulse
            longer than the fit window after the onset).
        """

        def get(*keys):
            node = config
            for n, key in enumerate(keys):
                if not isinstance(node, Mapping) or key not in node:
                    raise LoperInputError(
                        f"config: key '{'.'.join(keys[: n + 1])}' missing: the planner needs '{'.'.join(keys)}'"
                    )
                node = node[key]
            return copy.deepcopy(node)

        ident = {k: get("identification", k) for k in _PLAN_KEYS}
        for key in ("stiffness_bounds_nm_per_rad", "damping_bounds_nms_per_rad"):
            ident[key] = tuple(ident[key])
        return cls(
            onsets_ms=tuple(get("trials", "perturbation_onsets_ms")),
            strides=tuple(get("planning", "strides")),
            targets=tuple(get("planning", "targets")),
            plan=PlanSettings(
                pulse_force_n=get("planning", "pulse_force_n"),
                pulse_duration_s=get("planning", "pulse_duration_s"),
                **ident,
            ),
            response=ResponseSettings(
                window_before_s=get("identification", "window_before_s"),
                window_after_s=get("identification", "window_after_s"),
                initial_state_span_s=get("identification", "initial_state_span_s"),
                whisker=get("strides", "iqr_whisker"),
                max_fraction=get("strides", "max_outlier_fraction"),
                counterfactual=get("identification", "counterfactual"),
            ),
            device=DeviceParameters(**get("device", "parameters")),
            max_null_trial_ratio=get("identification", "max_null_trial_ratio"),
        )


@dataclass(frozen=True)
class PilotTrial:
    """A pilot trial walked with the device: its joint-angle and stride tables (TSV)."""

    angles: PathLike
    strides: PathLike


@dataclass(frozen=True)
class PilotFiles:
    """The pilot's files the planner reads.

    ``trials``: the pilot's trials walked with the device (name -> :class:`PilotTrial`): their unperturbed
    strides are the null pairs; the perturbed strides of the trials at an onset are its perturbed pairs
    (:func:`loper_analysis.planning.inputs.pilot_perturbed_pairs`), whose scatter the prediction takes
    (the null pairs' when there are none, with a note in the rows). ``segments``: the segment table of the
    subject to plan for (the pilot's, or another subject's). ``impedance``: impedance rows
    (``results/impedance/{subject}/{onset}.tsv`` or ``results/impedance/impedance.tsv``) whose pilot estimates
    are the planned impedance (none: the values are given to :func:`plan`).
    """

    trials: Mapping[str, PilotTrial]
    segments: PathLike
    impedance: tuple[PathLike, ...] = ()


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


def plan(
    files: PilotFiles,
    subject: str,
    settings: PlanningSettings,
    out_tsv: PathLike | None = None,
    answers_out: PathLike | None = None,
    *,
    impedance: Mapping[int, Sequence[float]] | Sequence[float] | None = None,
    unplannable: str = "raise",
    pool_scatter: bool = True,
) -> tuple[pd.DataFrame, list[str]]:
    """Predicted SD and 95 % CI half-width of K and D for a planned experiment, from a pilot subject.

    Parameters
    ----------
    files
        The pilot's trials with the device, the segment table of the subject to plan for and the impedance
        rows of the planned impedance (:class:`PilotFiles`).
    subject
        The pilot's ID (rows of the impedance tables, messages).
    settings
        Onsets after toe-off (ms), counts of perturbed strides, targets, the planned pulse (desired force,
        N; duration, s), the identification, response and device settings (:class:`PlanningSettings`).
    out_tsv, answers_out
        The table (:data:`loper_analysis.planning.precision.PLAN_COLUMNS`) and the text
        answers; None writes nothing.
    impedance
        Instead of the rows of ``files.impedance``: the planned impedance (6 values, order of
        ``PARAMETERS``), one set for every onset or ``{onset_ms: values}``.
    unplannable
        An onset whose pilot fit has no estimate (e.g. ``failed``) or whose
        null pairs are too few: ``raise`` stops with the onset and the cause;
        ``note`` writes its rows without a prediction, the cause in ``note``
        (the workflow's choice: a pilot onset that cannot serve does not stop the run).
    pool_scatter
        With perturbed pairs at two or more onsets, their excess scatter over
        the null pairs is pooled over the onsets
        (:func:`loper_analysis.planning.covariance.pool_onsets`); False: each onset its own.

    Returns
    -------
    (pandas.DataFrame, list of str)
        The table and the answers.
    """
    from loper_analysis.io.segment_table import read_segments
    from loper_analysis.planning.covariance import (
        conditional_stride_covariance,
        pool_onsets,
        stretch_covariances,
        stride_covariance,
    )
    from loper_analysis.planning.inputs import pilot_onset_series, pilot_perturbed_pairs
    from loper_analysis.planning.precision import precision_table, target_answer, unplanned_rows
    from loper_analysis.responses import null_pair_windows

    if unplannable not in ("raise", "note"):
        raise LoperInputError(f"unplannable must be 'raise' or 'note', got {unplannable!r}")
    if settings.onsets_ms is None:
        raise LoperInputError("planning settings: no onsets (onsets_ms) to plan for")
    plan_settings = settings.plan
    counts = list(settings.strides)
    for n in counts:  # checked before any work
        if isinstance(n, bool) or not float(n) == int(n) or int(n) < 1:
            raise LoperInputError(f"stride count must be a whole number >= 1 (perturbed strides averaged), got {n!r}")
    if not files.trials:
        raise LoperInputError(f"pilot {subject}: no trial walked with the device: the null pairs need one")
    response_settings = settings.response
    ratio = settings.max_null_trial_ratio
    dev = settings.device
    params = read_segments(files.segments)
    pool = [
        {"name": name, "angles": read_tsv(t.angles, "angle table"), "strides": read_tsv(t.strides, "stride table")}
        for name, t in files.trials.items()
    ]
    impedance_tsvs = files.impedance
    rows_table = None
    if impedance is None:
        if not impedance_tsvs:
            raise LoperInputError("planned impedance: give the pilot's impedance rows or the values")
        rows_table = pd.concat([read_tsv(f, "impedance rows") for f in impedance_tsvs], ignore_index=True)
    onsets_ms = settings.onsets_ms
    planned, failed, by_count = {}, {}, {}
    for onset in onsets_ms:
        where = f"pilot {subject}, onset {onset:g} ms"
        try:
            if impedance is None:
                values = planned_impedance(rows_table, subject, onset, ", ".join(map(str, impedance_tsvs)))
            else:
                values = np.asarray(impedance[onset] if isinstance(impedance, Mapping) else impedance, float)
            if response_settings.counterfactual == "conditional":
                series = pilot_onset_series(pool, onset, response_settings, source=subject)
                if series is None:
                    raise LoperInputError(
                        f"{where}: no trial of the pilot is perturbed at this onset: the conditional "
                        "counterfactual's plan takes the onset's own strides (or plan with "
                        "identification.counterfactual: matched_stride)"
                    )
                planned[onset] = conditional_stride_covariance(series, params, values, plan_settings, dev, source=where)
                by_count[onset] = stretch_covariances(
                    pool, onset, counts, params, values, plan_settings, dev, response_settings, source=where
                )
            else:
                null = null_pair_windows(pool, onset, response_settings, source=subject, max_trial_ratio=ratio)
                pairs = pilot_perturbed_pairs(pool, onset, response_settings, source=subject)
                planned[onset] = stride_covariance(
                    null, params, values, plan_settings, dev, source=where, perturbed_pairs=pairs
                )
        except LoperInputError as exc:
            if unplannable == "raise":
                raise
            log.warning("%s: not planned: %s", where, exc)
            failed[onset] = unplanned_rows(counts, onset, f"not planned: {exc}", subject, plan_settings)
    if pool_scatter:
        planned = pool_onsets(planned)
    tables, answers = [], []
    for onset in onsets_ms:
        if onset in failed:
            tables.append(failed[onset])
            continue
        sc = planned[onset]
        tables.append(precision_table(sc, counts, onset, subject, plan_settings, by_count.get(onset)))
        log.info(
            "pilot %s, onset %g ms: %d null pairs, %d perturbed pairs (scatter: %s); planned %s",
            subject,
            onset,
            sc.n_null_pairs,
            sc.n_perturbed_pairs,
            sc.scatter.replace("_", " "),
            ", ".join(f"{p} {v:.3g}" for p, v in zip(PARAMETERS, sc.impedance)),
        )
        for target in settings.targets:
            if target.get("onset_ms") is not None and float(target["onset_ms"]) != float(onset):
                continue
            answers.append(
                target_answer(
                    sc,
                    str(target["joint"]),
                    str(target["parameter"]),
                    onset,
                    percent=target.get("percent"),
                    half_width=target.get("half_width"),
                )
            )
    table = pd.concat(tables, ignore_index=True)
    if out_tsv is not None:
        write_tsv(table, out_tsv)
    if answers_out is not None:
        write_text(answers_out, "".join(a + "\n" for a in answers), "planning answers")
    for a in answers:
        log.info("%s", a)
    return table, answers
