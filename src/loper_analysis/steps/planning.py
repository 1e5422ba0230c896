"""File step of the experiment planner: a pilot subject's tables in, the predicted precision table out.

:func:`plan` reads the pilot's joint-angle and stride tables (the trials with
the device, whose unperturbed strides give the null pairs and whose perturbed
strides at an onset give that onset's perturbed pairs), its segment table
(or another subject's) and its impedance rows (the planned impedance), and
writes the table of :func:`loper_analysis.planning.precision.precision_table` for every
onset and the answers to the targets (method: ``docs/planning.md``).
"""

from __future__ import annotations

import copy
import logging
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, PARAMETERS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_text, write_tsv
from loper_analysis.io.readers import read_tsv

__all__ = ["LIBRARY_PLANNING_SETTINGS", "plan", "planned_impedance", "planning_settings"]

log = logging.getLogger(__name__)

#: Identification settings the planner follows (keys of config ``identification``).
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


#: Identification settings the rule passes to :func:`plan` (keys of config ``identification``): those the planner
#: follows and the null pairs' trial ratio.
_RULE_IDENTIFICATION_KEYS = (
    "window_before_s",
    "window_after_s",
    "initial_state_span_s",
    "initial_state_degree",
    "n_substeps",
    "null_pair_components",
    "min_null_pairs",
    "max_null_trial_ratio",
    "interval_scatter",
    "stiffness_bounds_nm_per_rad",
    "damping_bounds_nms_per_rad",
)

#: The settings of :func:`planning_settings` without a configuration (``loper-analysis plan`` with no config file):
#: ``onsets`` None (those of the pilot's impedance rows), no targets, and the library's own response,
#: identification and device defaults (None: :class:`~loper_analysis.responses.ResponseSettings`,
#: :class:`~loper_analysis.planning.precision.PlanSettings`,
#: :class:`~loper_analysis.device.controller.DeviceParameters`).
LIBRARY_PLANNING_SETTINGS = {
    "onsets": None,
    "strides": [10, 20, 40],
    "targets": [],
    "pulse_force_n": 40.0,
    "pulse_duration_s": 0.1,
    "response": None,
    "identification": None,
    "device": None,
}


def planning_settings(config: Mapping) -> dict:
    """The planner's settings from the workflow's configuration: the one mapping of config keys to :func:`plan`.

    The rule ``planning`` (its params) and ``loper-analysis plan`` both take
    their settings from here, so that the two cannot drift apart.

    Parameters
    ----------
    config : mapping
        The validated configuration (``config/config.yaml`` and its layers;
        :func:`loper_analysis.config_file.load_config`).

    Returns
    -------
    dict
        Keyword arguments of :func:`plan` by the rule's params' names (a copy:
        changing it leaves ``config`` as it is):

        ``onsets``
            ``trials.perturbation_onsets_ms`` (ms after toe-off).
        ``strides``
            ``planning.strides`` (perturbed strides averaged).
        ``targets``
            ``planning.targets`` (``joint``, ``parameter``, ``percent`` or
            ``half_width`` in N·m/rad or N·m·s/rad, optional ``onset_ms``).
        ``pulse_force_n``, ``pulse_duration_s``
            ``planning.pulse_force_n`` (N) and ``planning.pulse_duration_s`` (s).
        ``response``
            :class:`~loper_analysis.responses.ResponseSettings` keywords:
            ``window_before_s``, ``window_after_s``, ``initial_state_span_s``
            (s) of ``identification``; ``whisker`` and ``max_fraction`` of
            ``strides.iqr_whisker`` and ``strides.max_outlier_fraction``.
        ``identification``
            The keys of ``identification`` the planner follows: fit window and
            initial state (s), substeps, projected components, null-pair
            minimum and trial ratio, interval scatter and the K, D bounds
            (N·m/rad, N·m·s/rad).
        ``device``
            ``device.parameters``
            (:class:`~loper_analysis.device.controller.DeviceParameters` keywords).

    Raises
    ------
    LoperInputError
        A key the planner needs is missing (naming it).
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

    return {
        "onsets": get("trials", "perturbation_onsets_ms"),
        "strides": get("planning", "strides"),
        "targets": get("planning", "targets"),
        "pulse_force_n": get("planning", "pulse_force_n"),
        "pulse_duration_s": get("planning", "pulse_duration_s"),
        "response": {
            "window_before_s": get("identification", "window_before_s"),
            "window_after_s": get("identification", "window_after_s"),
            "initial_state_span_s": get("identification", "initial_state_span_s"),
            "whisker": get("strides", "iqr_whisker"),
            "max_fraction": get("strides", "max_outlier_fraction"),
        },
        "identification": {k: get("identification", k) for k in _RULE_IDENTIFICATION_KEYS},
        "device": get("device", "parameters"),
    }


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


def _settings(pulse_force_n: float, pulse_duration_s: float, identification: Mapping | None):
    from loper_analysis.planning.precision import PlanSettings

    ident = {k: v for k, v in (identification or {}).items() if k in _PLAN_KEYS}
    for key in ("stiffness_bounds_nm_per_rad", "damping_bounds_nms_per_rad"):
        if key in ident:
            ident[key] = tuple(ident[key])
    return PlanSettings(pulse_force_n=pulse_force_n, pulse_duration_s=pulse_duration_s, **ident)


def plan(
    trials: Sequence[str],
    angles: Sequence[PathLike],
    strides: Sequence[PathLike],
    segments_tsv: PathLike,
    subject: str,
    onsets_ms: Sequence[int],
    n_strides: Sequence[int],
    out_tsv: PathLike | None = None,
    answers_out: PathLike | None = None,
    *,
    impedance_tsvs: Sequence[PathLike] = (),
    impedance: Mapping[int, Sequence[float]] | Sequence[float] | None = None,
    targets: Sequence[Mapping] = (),
    pulse_force_n: float = 40.0,
    pulse_duration_s: float = 0.1,
    response: Mapping | None = None,
    identification: Mapping | None = None,
    device: Mapping | None = None,
    unplannable: str = "raise",
    pool_scatter: bool = True,
) -> tuple[pd.DataFrame, list[str]]:
    """Predicted SD and 95 % CI half-width of K and D for a planned experiment, from a pilot subject.

    Parameters
    ----------
    trials, angles, strides
        The pilot's trials walked with the device (names) and their angle and
        stride tables (TSV, same order): their unperturbed strides are the null
        pairs; the perturbed strides of the trials at an onset are its
        perturbed pairs (:func:`loper_analysis.planning.precision.pilot_perturbed_pairs`),
        whose scatter the prediction takes (the null pairs' when there are
        none, with a note in the rows).
    segments_tsv
        Segment table of the subject to plan for (the pilot's, or another subject's).
    subject
        The pilot's ID (rows of the impedance tables, messages).
    onsets_ms, n_strides
        Onsets after toe-off (ms) and counts of perturbed strides to predict for.
    out_tsv, answers_out
        The table (:data:`loper_analysis.planning.precision.PLAN_COLUMNS`) and the text
        answers; None writes nothing.
    impedance_tsvs
        Impedance rows (``results/impedance/{subject}/{onset}.tsv`` or
        ``results/tables/impedance.tsv``): the pilot's estimates are the planned impedance.
    impedance
        Instead: the planned impedance (6 values, order of ``PARAMETERS``), one
        set for every onset or ``{onset_ms: values}``.
    targets
        Each ``joint``, ``parameter`` (``K``/``D``), ``percent`` or
        ``half_width`` (N·m/rad, N·m·s/rad) and optionally ``onset_ms`` (else every onset).
    pulse_force_n, pulse_duration_s
        The planned pulse (desired force, N; duration, s).
    response, identification, device
        Keyword arguments of :class:`~loper_analysis.responses.ResponseSettings`,
        the identification settings (config ``identification``) and
        :class:`~loper_analysis.device.controller.DeviceParameters`.
    unplannable
        An onset whose pilot fit has no estimate (e.g. ``failed``) or whose
        null pairs are too few: ``raise`` stops with the onset and the cause;
        ``note`` writes its rows without a prediction, the cause in ``note``
        (the workflow's choice: a pilot onset that cannot serve does not stop the run).
    pool_scatter
        With perturbed pairs at two or more onsets, their excess scatter over
        the null pairs is pooled over the onsets
        (:func:`loper_analysis.planning.precision.pool_onsets`); False: each onset its own.

    Returns
    -------
    (pandas.DataFrame, list of str)
        The table and the answers.
    """
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.planning.precision import (
        pilot_perturbed_pairs,
        pool_onsets,
        precision_table,
        stride_covariance,
        target_answer,
        unplanned_rows,
    )
    from loper_analysis.responses import MAX_TRIAL_DEVIATION_RATIO, ResponseSettings, null_pair_windows
    from loper_analysis.swing_leg.dynamics import read_segments

    if unplannable not in ("raise", "note"):
        raise LoperInputError(f"unplannable must be 'raise' or 'note', got {unplannable!r}")
    settings = _settings(pulse_force_n, pulse_duration_s, identification)
    counts = list(n_strides)
    for n in counts:  # checked before any work
        if isinstance(n, bool) or not float(n) == int(n) or int(n) < 1:
            raise LoperInputError(f"stride count must be a whole number >= 1 (perturbed strides averaged), got {n!r}")
    if not trials:
        raise LoperInputError(f"pilot {subject}: no trial walked with the device: the null pairs need one")
    response_settings = ResponseSettings(**(response or {}))
    ratio = (identification or {}).get("max_null_trial_ratio", MAX_TRIAL_DEVIATION_RATIO)
    dev = DeviceParameters(**(device or {}))
    params = read_segments(segments_tsv)
    pool = [
        {"name": name, "angles": read_tsv(a, "angle table"), "strides": read_tsv(s, "stride table")}
        for name, a, s in zip(trials, angles, strides, strict=True)
    ]
    rows_table = None
    if impedance is None:
        if not impedance_tsvs:
            raise LoperInputError("planned impedance: give the pilot's impedance rows or the values")
        rows_table = pd.concat([read_tsv(f, "impedance rows") for f in impedance_tsvs], ignore_index=True)
    planned, failed = {}, {}
    for onset in onsets_ms:
        where = f"pilot {subject}, onset {onset:g} ms"
        try:
            if impedance is None:
                values = planned_impedance(rows_table, subject, onset, ", ".join(map(str, impedance_tsvs)))
            else:
                values = np.asarray(impedance[onset] if isinstance(impedance, Mapping) else impedance, float)
            null = null_pair_windows(pool, onset, response_settings, source=subject, max_trial_ratio=ratio)
            pairs = pilot_perturbed_pairs(pool, onset, response_settings, source=subject)
            planned[onset] = stride_covariance(null, params, values, settings, dev, source=where, perturbed_pairs=pairs)
        except LoperInputError as exc:
            if unplannable == "raise":
                raise
            log.warning("%s: not planned: %s", where, exc)
            failed[onset] = unplanned_rows(counts, onset, f"not planned: {exc}", subject, settings)
    if pool_scatter:
        planned = pool_onsets(planned)
    tables, answers = [], []
    for onset in onsets_ms:
        if onset in failed:
            tables.append(failed[onset])
            continue
        sc = planned[onset]
        tables.append(precision_table(sc, counts, onset, subject, settings))
        log.info(
            "pilot %s, onset %g ms: %d null pairs, %d perturbed pairs (scatter: %s); planned %s",
            subject,
            onset,
            sc.n_null_pairs,
            sc.n_perturbed_pairs,
            sc.scatter.replace("_", " "),
            ", ".join(f"{p} {v:.3g}" for p, v in zip(PARAMETERS, sc.impedance)),
        )
        for target in targets:
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
