"""The ``strides`` step: a trial's strides of one leg, their outliers and cycles; the summary over trials.

:func:`strides` (one trial, settings :class:`loper_analysis.gait.stride_settings.StrideSettings` from the
config) and :func:`strides_summary` (every trial of the study).
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.gait.outliers import MIN_VALID_STRIDES
from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.gait.strides import DROPPED_COLUMNS, MAX_OUTSIDE_LOG_FRACTION
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_tsv

__all__ = ["TrialTables", "strides", "strides_summary"]

log = logging.getLogger(__name__)


def strides(
    angles_tsv: PathLike,
    events_tsv: PathLike,
    strides_out: PathLike,
    cycles_out: PathLike,
    force_tsv: PathLike | None = None,
    settings: StrideSettings = StrideSettings(),
    dropped_out: PathLike | None = None,
):
    """Strides of one leg, their outlier verdicts and the time-normalised cycles of one trial.

    ``settings`` (:class:`StrideSettings`): the leg, the samples per cycle and the IQR rule.

    Writes the stride table and the cycles (:func:`loper_analysis.gait.strides.stride_tables`), and
    (``dropped_out``) the strides with events that could not be cut: frames left out of IK, or outside the robot
    log's span (a truncated log, warned about);
    returns the :class:`~loper_analysis.gait.strides.StrideTables`. A trial with 0
    or 1 strides of the leg is written like any other (the stride table with
    all its columns, without rows for 0 strides) and flagged ``too_few_strides``.
    """
    from loper_analysis.gait.strides import stride_tables

    sources = {"angles": str(angles_tsv), "events": str(events_tsv), "force": str(force_tsv)}
    force = None if force_tsv is None else read_tsv(force_tsv, "force table", ("time_s", "force_measured_n"))
    tables = stride_tables(
        read_tsv(angles_tsv, "angle table"),
        read_tsv(events_tsv, "event table"),
        force,
        side=settings.side,
        n_points=settings.n_points,
        whisker=settings.whisker,
        max_fraction=settings.max_fraction,
        min_valid=settings.min_valid,
        sources=sources,
    )
    write_tsv(tables.cycles, cycles_out)
    if dropped_out is not None:
        write_tsv(tables.dropped, dropped_out)
    write_tsv(tables.strides, strides_out)
    s = tables.strides
    log.info("%d strides, %d kept", len(s), int((~s["removed"]).sum()))
    return tables


#: Columns of the IK summaries the strides summary reads.
IK_COLUMNS: tuple[str, ...] = (
    "n_frames",
    "n_frames_left_out",
    "marker_rms_mean_m",
    "worst_marker",
    "worst_marker_rms_m",
    "marker_geometry_change",
    "warnings",
)


@dataclass(frozen=True)
class TrialTables:
    """The per-trial tables the strides summary adds (each a sequence of paths in the order of the trials, or
    None).

    Attributes
    ----------
    contacts : force-plate contact tables (:func:`loper_analysis.stages.events.step.events`).
    ik : IK summaries (:func:`loper_analysis.stages.ik.step.ik_trial`).
    markers : markers summaries (:func:`loper_analysis.stages.markers.step.markers`).
    agreement : our angles against the lab's own (:func:`loper_analysis.stages.ik.step.ik_trial`).
    dropped : strides that could not be cut (:func:`strides`).
    """

    contacts: Sequence[PathLike] | None = None
    ik: Sequence[PathLike] | None = None
    markers: Sequence[PathLike] | None = None
    agreement: Sequence[PathLike] | None = None
    dropped: Sequence[PathLike] | None = None


def strides_summary(
    subject_trials: Sequence[tuple[str, str]],
    strides_tsvs: Sequence[PathLike],
    out_tsv: PathLike,
    min_valid: int = MIN_VALID_STRIDES,
    files: TrialTables = TrialTables(),
) -> pd.DataFrame:
    """One row per subject x trial of the stride tables (:func:`loper_analysis.gait.strides.stride_summary`).

    ``strides_tsvs`` holds one stride table per ``(subject, trial)`` of
    ``subject_trials``, in order; of ``files`` (:class:`TrialTables`, same order), ``contacts`` the
    force-plate contact tables written by :func:`events`, whose flagged
    contacts are counted and, with their reasons, added to the trial's warnings. A stride table of a
    trial with 0 strides (its header only, as :func:`strides` writes it) gives ``n_strides`` 0 and the
    status ``too_few_strides``. ``ik`` (the IK summaries of
    :func:`loper_analysis.stages.ik.step.ik_trial`) add the frames and those left
    out of IK, the mean marker RMS error, the worst marker, the change of the marker geometry against the
    model and the IK warnings, ``markers`` (the markers
    summaries of :func:`markers`) the trial's walking direction and the turn that made it walk along +X, and
    first among the warnings a trial that is not level walking (its pelvis's rise or fall, its plates'
    heights: :mod:`loper_analysis.motion.level_walking`),
    ``agreement`` (our angles against the lab's own, :func:`loper_analysis.stages.ik.step.ik_trial`) the least
    correlation and the largest RMS difference over the hip, knee and ankle angles compared (NaN where the file
    holds none), ``dropped`` (the strides :func:`strides` could not cut) the strides outside the robot log's span:
    beyond :data:`loper_analysis.gait.strides.MAX_OUTSIDE_LOG_FRACTION` of a trial's strides, its status is
    ``log_truncated`` and its warnings say so.

    Raises
    ------
    LoperInputError
        A stride table without the columns
        :data:`loper_analysis.gait.strides.SUMMARY_COLUMNS` (naming the file).
    """
    from loper_analysis.checks import require_columns
    from loper_analysis.gait.strides import SUMMARY_COLUMNS, stride_summary

    keys = [tuple(key) for key in subject_trials]
    tables = {
        key: require_columns(
            read_tsv(path, "stride table", keep_default_na=False, na_values=[""]),
            SUMMARY_COLUMNS,
            str(path),
            "stride table",
        )
        for key, path in zip(keys, strides_tsvs, strict=True)
    }
    contacts = None
    if files.contacts is not None:
        contacts = {
            key: read_tsv(path, "contact table", ("flag",), keep_default_na=False)
            for key, path in zip(keys, files.contacts, strict=True)
        }
    dropped = None
    if files.dropped is not None:
        dropped = {
            key: read_tsv(path, "dropped strides", DROPPED_COLUMNS, keep_default_na=False)
            for key, path in zip(keys, files.dropped, strict=True)
        }
    table = stride_summary(tables, min_valid, contacts, dropped)
    extra, ik_warnings, level_warnings = [], None, None
    if files.ik is not None:
        columns, ik_warnings = _ik_columns(files.ik)
        extra.append(columns)
    if files.markers is not None:
        columns, level_warnings = _marker_columns(files.markers)
        extra.append(columns)
    if files.agreement is not None:
        extra.append(_agreement_columns(files.agreement))
    if ik_warnings is not None:
        extra.append(pd.DataFrame({"warnings": ik_warnings}))
    if extra:
        table = pd.concat([table, *extra], axis=1)
    if "outside_robot_log_fraction" in table:
        table["warnings"] = _with_truncation_warnings(table)
    if contacts is not None:
        table["warnings"] = _with_contact_warnings(table, contacts)
    if level_warnings is not None:
        before = table["warnings"].fillna("") if "warnings" in table else [""] * len(table)
        table["warnings"] = [" | ".join(w for w in pair if w) for pair in zip(level_warnings, before)]
    write_tsv(table, out_tsv)
    for row in table[table.status == "too_few_strides"].itertuples():
        log.warning("%s %s: only %d valid strides (minimum %d)", row.subject, row.trial, row.n_kept, min_valid)
    if "warnings" in table:
        for row in table[table["warnings"] != ""].itertuples():
            log.warning("%s %s: %s", row.subject, row.trial, row.warnings)
    log.info("strides:\n%s", table.to_string(index=False))
    return table


def _ik_columns(paths: Sequence[PathLike]) -> tuple[pd.DataFrame, list[str]]:
    """The strides summary's columns from the trials' IK summaries, and their warnings."""
    ik = [read_tsv(path, "IK summary", IK_COLUMNS, keep_default_na=False, na_values=[""]).iloc[0] for path in paths]
    columns = pd.DataFrame(
        {
            "n_frames": [int(r.n_frames) for r in ik],
            "n_frames_left_out": [int(r.n_frames_left_out) for r in ik],
            "marker_rms_mean_m": [float(r.marker_rms_mean_m) for r in ik],
            "worst_marker": ["" if pd.isna(r.worst_marker) else str(r.worst_marker) for r in ik],
            "worst_marker_rms_m": [float(r.worst_marker_rms_m) for r in ik],
            "marker_geometry_change": [float(r.marker_geometry_change) for r in ik],
        }
    )
    return columns, ["" if pd.isna(r.warnings) else str(r.warnings) for r in ik]


def _marker_columns(paths: Sequence[PathLike]) -> tuple[pd.DataFrame, list[str]]:
    """The trials' walking direction, speed and turn, from their markers summaries, and their level-walking
    warnings (:mod:`loper_analysis.motion.level_walking`; '' for a level walk)."""
    marks = [read_tsv(path, "markers summary", ("heading_deg", "speed_m_per_s", "turn_deg")).iloc[0] for path in paths]
    columns = pd.DataFrame(
        {
            "heading_deg": [float(r.heading_deg) for r in marks],
            "speed_m_per_s": [float(r.speed_m_per_s) for r in marks],
            "turn_deg": [float(r.turn_deg) for r in marks],
        }
    )
    return columns, ["" if pd.isna(r.get("warnings", "")) else str(r.get("warnings", "")) for r in marks]


def _agreement_columns(paths: Sequence[PathLike]) -> pd.DataFrame:
    """The least r and the largest RMS difference over the hip, knee and ankle angles against the lab's own."""
    agree = [read_tsv(path, "lab agreement", ("angle", "r", "rms_diff_rad")) for path in paths]
    joints = [a[a["angle"] != "pelvis_angle"] if len(a) else a for a in agree]
    return pd.DataFrame(
        {
            "lab_joints_min_r": [float(a["r"].min()) if len(a) else np.nan for a in joints],
            "lab_joints_max_rms_diff_rad": [float(a["rms_diff_rad"].max()) if len(a) else np.nan for a in joints],
        }
    )


def _with_truncation_warnings(table: pd.DataFrame) -> list[str]:
    """The summary's warnings, each trial whose strides lie outside its robot log beyond
    :data:`loper_analysis.gait.strides.MAX_OUTSIDE_LOG_FRACTION` warned about first."""
    said = [
        f"robot log truncated? {n} of the strides with events ({100 * f:.0f} %) lie outside its span"
        if f > MAX_OUTSIDE_LOG_FRACTION
        else ""
        for n, f in zip(table["n_outside_robot_log"], table["outside_robot_log_fraction"])
    ]
    before = table["warnings"] if "warnings" in table else pd.Series([""] * len(table))
    return [" | ".join(w for w in pair if w) for pair in zip(said, before.fillna(""))]


def _with_contact_warnings(table: pd.DataFrame, contacts: dict) -> list[str]:
    """The summary's warnings, with each trial's force-plate contacts left out of the events and their reasons
    (the contact tables' ``reason`` column; contacts cut by the recording's start or end are no warning)."""
    before = table["warnings"].fillna("") if "warnings" in table else pd.Series([""] * len(table))
    out = []
    for subject, trial, said in zip(table["subject"], table["trial"], before):
        c = contacts[(subject, trial)]
        lost = c[~c["flag"].isin(["ok", "incomplete"])] if len(c) and "reason" in c else c.iloc[:0]
        lines = [
            f"plate {r.plate} contact {float(r.start_s):.3f}-{float(r.end_s):.3f} s left out of the events "
            f"({r.flag}): {r.reason}"
            for r in lost.itertuples()
        ]
        out.append(" | ".join(w for w in [str(said), *lines] if w))
    return out


def angles_figure(
    angles_tsv: PathLike,
    events_tsv: PathLike,
    out_png: PathLike,
    lab_angles_tsv: PathLike | None = None,
    title: str | None = None,
) -> None:
    """Both sides' joint angles over the gait cycle, mean ± SD over the strides found from the events, with the
    lab's own angles where the file holds them (:func:`loper_analysis.report.figures.gait.stride_angles_figure`),
    as a PNG."""
    from loper_analysis.io.atomic import write_figure
    from loper_analysis.report.figures.gait import stride_angles_figure

    angles = read_tsv(angles_tsv, "angle table", ("time_s",))
    events = read_tsv(events_tsv, "event table", ("side", "event", "time_s"))
    lab = None if lab_angles_tsv is None else read_tsv(lab_angles_tsv, "lab angles", ("time_s",))
    write_figure(stride_angles_figure(angles, events, lab, title), out_png)
