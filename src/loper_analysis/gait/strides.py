"""Strides of one leg from the joint angles, the gait events and the interaction force; outliers; cycles.

* :func:`strides_from_events` - the stride table of one side from an event
  table (heel strike -> heel strike, with its toe-off), leaving out strides
  that span a flagged contact;
* :func:`stride_tables` - the stride table (absolute times, perturbed flag,
  outlier verdicts, interaction force per phase) and the time-normalised
  cycles (stride, stance, swing) of one trial;
* :func:`stride_summary` - one row per trial: strides found, removed, kept, status;
* :func:`phase_cycles` - the normalised cycles of one phase as an array.

Times in s on the motion-capture clock, angles in rad, force in N.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.checks import bool_column, require_columns, where
from loper_analysis.checks import side as check_side
from loper_analysis.constants import FLAGGED_EVENTS, JOINTS, angle_column
from loper_analysis.device.loadcell import perturbation_onsets
from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.cycles import cycles_table
from loper_analysis.gait.outliers import (
    IQR_WHISKER,
    MAX_OUTLIER_FRACTION,
    MIN_STRIDES_FOR_OUTLIERS,
    MIN_VALID_STRIDES,
    check_enough_strides,
    iqr_outliers,
)
from loper_analysis.gait.resampling import N_POINTS, PHASE_BOUNDS, normalise
from loper_analysis.study_design import PERTURBED_SIDE

__all__ = [
    "STRIDE_COLUMNS",
    "FORCE_PHASES",
    "SUMMARY_COLUMNS",
    "DROPPED_COLUMNS",
    "MAX_OUTSIDE_LOG_FRACTION",
    "StrideTables",
    "strides_from_events",
    "force_phase_metrics",
    "stride_tables",
    "stride_summary",
    "phase_cycles",
]

log = logging.getLogger(__name__)

#: Columns of the stride table from the events (:func:`strides_from_events`).
STRIDE_COLUMNS: tuple[str, ...] = (
    "stride",
    "side",
    "heel_strike_s",
    "toe_off_s",
    "end_s",
    "duration_s",
    "stance_s",
    "swing_s",
)
#: Phases of the interaction-force metrics (half-open sample sets).
FORCE_PHASES: tuple[str, ...] = ("stance", "swing")
#: Columns of a stride table that :func:`stride_summary` reads.
SUMMARY_COLUMNS: tuple[str, ...] = ("removed", "reason", "duration_s")
#: Columns of the table of strides with events that could not be cut (:attr:`StrideTables.dropped`).
DROPPED_COLUMNS: tuple[str, ...] = ("heel_strike_s", "end_s", "reason")
#: Share of a trial's strides outside its robot log's span above which the trial's status is ``log_truncated``.
MAX_OUTSIDE_LOG_FRACTION: float = 0.1


def strides_from_events(events: pd.DataFrame, side: str) -> pd.DataFrame:
    """Stride table of one side from an event table.

    A stride runs from a heel strike to the next heel strike of the same side
    and must contain exactly one toe-off (strictly between the two); strides
    without one (or with several) are dropped, as are the incomplete strides
    before the first and after the last heel strike.

    Event tables of force-plate contacts (:func:`loper_analysis.gait.contacts.contact_events`)
    also hold ``flagged_start`` / ``flagged_end`` rows: the span of a contact
    that gave no event. A stride whose swing (toe-off -> next heel strike)
    overlaps such a span of its side (``flagged_start < end`` and
    ``flagged_end > toe_off``) is dropped: a contact of that foot may hide in
    it, so the "stride" may be two. A flagged span during the stride's stance
    cannot hide a contact of the same foot (it stands on the contact that gave
    the heel strike) and leaves the stride in. Tables without these rows give
    the same strides as before.

    Parameters
    ----------
    events : pandas.DataFrame
        Columns ``side``, ``event``, ``time_s`` as returned by :func:`loper_analysis.gait.events.gait_events`
        (tables of both sides may be concatenated) or
        :func:`loper_analysis.gait.contacts.contact_events`.
    side : {"left", "right"}

    Returns
    -------
    pandas.DataFrame
        One row per complete stride, in time order: ``stride`` (0, 1, ... over
        the kept strides), ``side``, ``heel_strike_s`` (start), ``toe_off_s``,
        ``end_s`` (next heel strike), ``duration_s`` = end - start,
        ``stance_s`` = toe-off - start, ``swing_s`` = end - toe-off; all in s.
        Empty (with these columns) when the side has fewer than two heel strikes.

    Raises
    ------
    LoperInputError
        Missing columns, an unknown side, non-finite event times, or
        ``flagged_start`` / ``flagged_end`` rows that do not pair up.
    """
    source = str(events.attrs.get("source", "")) if isinstance(events, pd.DataFrame) else ""
    if not isinstance(events, pd.DataFrame) or not {"side", "event", "time_s"} <= set(events.columns):
        raise LoperInputError(f"{where(source)}events must be a table with columns side, event, time_s")
    side = check_side(side, source)
    mine = events[events["side"] == side]
    t = mine["time_s"].to_numpy(dtype=float)
    if not np.isfinite(t).all():
        raise LoperInputError(f"{where(source)}events: time_s is not finite for the {side} side")
    hs = np.sort(t[mine["event"].to_numpy() == "heel_strike"])
    to = np.sort(t[mine["event"].to_numpy() == "toe_off"])
    start, end = hs[:-1], hs[1:]
    first = np.searchsorted(to, start, side="right")  # first toe-off after the start
    count = np.searchsorted(to, end, side="left") - first  # toe-offs strictly inside
    keep = count == 1
    flag_start, flag_end = _flagged_spans(mine, t, side, source)
    if flag_start.size and keep.any():
        swing_start = to[np.minimum(first, to.size - 1)]  # the stride's toe-off where keep (keep needs one)
        # a flagged span overlaps the swing [toe-off, end] when it begins before the end and ends after the toe-off
        overlaps = (flag_start[None, :] < end[:, None]) & (flag_end[None, :] > swing_start[:, None])
        spanning = keep & overlaps.any(axis=1)
        if spanning.any():
            log.info(
                "%s%s side: %d stride(s) whose swing overlaps a flagged contact are left out",
                where(source),
                side,
                int(spanning.sum()),
            )
        keep &= ~spanning
    start, end = start[keep], end[keep]
    toe_off = to[first[keep]] if to.size else np.empty(0)
    return pd.DataFrame(
        {
            "stride": np.arange(start.size, dtype=np.int64),
            "side": side,
            "heel_strike_s": start,
            "toe_off_s": toe_off,
            "end_s": end,
            "duration_s": end - start,
            "stance_s": toe_off - start,
            "swing_s": end - toe_off,
        },
        columns=list(STRIDE_COLUMNS),
    )


def _flagged_spans(mine: pd.DataFrame, t: np.ndarray, side: str, source: str) -> tuple[np.ndarray, np.ndarray]:
    """Start and end times (s) of the flagged contacts in one side's event rows, paired in time order."""
    kind = mine["event"].to_numpy()
    a = np.sort(t[kind == FLAGGED_EVENTS[0]])
    b = np.sort(t[kind == FLAGGED_EVENTS[1]])
    if a.size != b.size or np.any(b < a):
        raise LoperInputError(
            f"{where(source)}events: {a.size} {FLAGGED_EVENTS[0]} and {b.size} {FLAGGED_EVENTS[1]} row(s) "
            f"of the {side} side do not pair up (each flagged contact needs a start and a later end)"
        )
    return a, b


@dataclass
class StrideTables:
    """The stride table and the normalised cycles of one trial (:func:`stride_tables`).

    ``too_few_strides``: fewer unperturbed strides kept than required. ``dropped``: the strides with events that
    could not be cut (columns :data:`DROPPED_COLUMNS`; ``reason`` ``ik_frames_left_out`` or
    ``outside_robot_log``).
    """

    strides: pd.DataFrame
    cycles: pd.DataFrame
    too_few_strides: bool
    dropped: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=list(DROPPED_COLUMNS)))


def force_phase_metrics(time_s, force_n, stride_table: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """RMS and largest absolute interaction force per stride and phase.

    The phases are half-open sample sets: stance = samples with
    ``heel_strike_s <= t < toe_off_s``, swing = ``toe_off_s <= t < end_s``,
    so every sample belongs to at most one phase. RMS is the root of the mean
    square over those samples (equal weights: uniform sampling assumed).
    ``time_s`` and the stride table must share one clock (synchronised
    robot log and treadmill).

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Times of the force samples in s, finite and strictly increasing.
    force_n : array_like, shape (n_samples,)
        Interaction force in N, finite.
    stride_table : pandas.DataFrame
        Columns ``stride``, ``heel_strike_s``, ``toe_off_s``, ``end_s``
        (:func:`strides_from_events`); every phase must lie inside
        ``time_s[0] .. time_s[-1]`` and hold at least one sample.
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    pandas.DataFrame
        One row per stride and phase (stride order, stance before swing):
        ``stride``, ``phase`` (``stance`` | ``swing``), ``rms_force_n``,
        ``max_abs_force_n`` (N).

    Raises
    ------
    LoperInputError
        Bad shapes, non-finite or non-increasing input, missing columns, a
        phase outside the data or without samples.
    """
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if t.ndim != 1 or f.shape != t.shape or t.size < 2:
        raise LoperInputError(f"{where(source)}time_s {t.shape} and force_n {f.shape} must be 1-D of equal length >= 2")
    for name, a in (("time_s", t), ("force_n", f)):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise LoperInputError(f"{where(source)}{name} is not finite at sample {bad[0]}: {a[bad[0]]}")
    if np.any(np.diff(t) <= 0):
        i = int(np.flatnonzero(np.diff(t) <= 0)[0]) + 1
        raise LoperInputError(f"{where(source)}time_s must increase strictly; sample {i} does not")
    needed = {"stride", "heel_strike_s", "toe_off_s", "end_s"}
    if not needed <= set(stride_table.columns):
        raise LoperInputError(
            f"{where(source)}stride_table lacks column(s) {sorted(needed - set(stride_table.columns))}"
        )
    square = np.concatenate([[0.0], np.cumsum(f * f)])
    absf = np.abs(f)
    rms, peak = [], []
    for phase in FORCE_PHASES:
        a = stride_table[PHASE_BOUNDS[phase][0]].to_numpy(float)
        b = stride_table[PHASE_BOUNDS[phase][1]].to_numpy(float)
        out = np.flatnonzero(~((a >= t[0]) & (b <= t[-1]) & (a < b)))
        if out.size:
            r = out[0]
            raise LoperInputError(
                f"{where(source)}stride {stride_table['stride'].iloc[r]} {phase} "
                f"({float(a[r])!r} .. {float(b[r])!r} s) "
                f"is empty or outside the force data ({float(t[0])!r} .. {float(t[-1])!r} s)"
            )
        lo = np.searchsorted(t, a, side="left")
        hi = np.searchsorted(t, b, side="left")
        empty = np.flatnonzero(hi <= lo)
        if empty.size:
            r = empty[0]
            raise LoperInputError(
                f"{where(source)}stride {stride_table['stride'].iloc[r]} {phase} holds no force sample"
            )
        rms.append(np.sqrt((square[hi] - square[lo]) / (hi - lo)))
        peak.append(np.array([absf[i:j].max() for i, j in zip(lo, hi)]))  # a loop per stride, not per sample
    n_phases = len(FORCE_PHASES)
    return pd.DataFrame(
        {
            "stride": np.repeat(stride_table["stride"].to_numpy(), n_phases),
            "phase": np.tile(FORCE_PHASES, len(stride_table)),
            "rms_force_n": np.column_stack(rms).ravel(),
            "max_abs_force_n": np.column_stack(peak).ravel(),
        }
    )


def stride_tables(
    angles: pd.DataFrame,
    events: pd.DataFrame,
    force: pd.DataFrame | None = None,
    *,
    side: str = PERTURBED_SIDE,
    n_points: int = N_POINTS,
    whisker: float = IQR_WHISKER,
    max_fraction: float = MAX_OUTLIER_FRACTION,
    min_valid: int = MIN_VALID_STRIDES,
    sources: Mapping[str, str] | None = None,
) -> StrideTables:
    """Strides of one leg, their outlier verdicts and the time-normalised cycles.

    Strides run heel strike to heel strike of ``side`` (``events``:
    :func:`loper_analysis.gait.events.gait_events`), kept only where the joint
    angles cover them without a gap (frames left out of IK are NaN) and,
    with a force table, where the robot log does. Outliers:
    :func:`loper_analysis.gait.outliers.iqr_outliers` on the stride-normalised
    hip, knee and ankle angles of the unperturbed strides.

    Parameters
    ----------
    angles : pandas.DataFrame
        ``time_s`` and ``{hip,knee,ankle}_<side>_rad`` per motion-capture frame.
    events : pandas.DataFrame
        ``side``, ``event``, ``time_s`` of both legs.
    force : pandas.DataFrame, optional
        The interaction force on the same frames (``time_s``,
        ``force_measured_n``, optional ``perturbation`` 0/1 flag; NaN outside
        the robot log), for trials walked with the device.
    side : {"left", "right"}
    n_points : int
        Samples per normalised stride, stance or swing.
    whisker, max_fraction : float
        Settings of the IQR rule.
    min_valid : int
        Fewest kept unperturbed strides without a warning.
    sources : mapping, optional
        Names (files) of ``angles``, ``events`` and ``force``, quoted in messages.

    Returns
    -------
    StrideTables
        ``strides``: one row per stride, absolute times (s), ``perturbed`` and
        its ``onset_s``, ``fraction_outlying_*``, ``removed``, ``reason``
        (``perturbed`` for perturbed strides, which the response analysis
        judges in their window) and, with a force table, RMS and max |F| per
        phase (N); ``cycles``: one row per stride x phase x normalised sample
        (``stride``, ``phase``, ``point``, ``percent``, the joint angles in rad
        and ``force_n``). Fewer than ``min_valid`` kept strides: a
        :class:`~loper_analysis.errors.TooFewStridesWarning` and
        ``too_few_strides`` True. Fewer than
        :data:`~loper_analysis.gait.outliers.MIN_STRIDES_FOR_OUTLIERS` unperturbed strides (none at all
        included): the outlier rule cannot judge them, so none is removed,
        their ``fraction_outlying_*`` are NaN and a warning says so.

    Raises
    ------
    LoperInputError
        Missing columns, force frames that differ from the angles'.
    """
    names = {"angles": "angles", "events": "events", "force": "force", **(sources or {})}
    cols = [angle_column(j, side) for j in JOINTS]
    require_columns(angles, ["time_s", *cols], names["angles"])
    table = strides_from_events(events, side)
    t = angles["time_s"].to_numpy(float)
    inside = (table["heel_strike_s"] >= t[0]) & (table["end_s"] <= t[-1])
    table = table[inside].reset_index(drop=True)
    values = angles[cols].to_numpy(float)
    n_with_events = len(table)
    table, lost = _strides_without_ik_gaps(table, t, values, names["angles"])
    dropped = [lost]
    force_n = None
    if force is not None:
        if len(force) != len(angles) or not np.allclose(force["time_s"].to_numpy(float), t, atol=1e-6):
            raise LoperInputError(f"{names['force']}: frames differ from the kinematics in {names['angles']}")
        force_n = force["force_measured_n"].to_numpy(float)
        table, lost = _strides_inside_robot_log(table, t, force_n, n_with_events, names["force"])
        if lost is not None:
            dropped.append(lost)
    perturbation = None if force_n is None or "perturbation" not in force.columns else force["perturbation"]
    table = _with_perturbations(table, t, perturbation)
    by_stride = normalise(t, values, table, "stride", n_points, source=names["angles"])
    joint_names = [c.split("_")[0] for c in cols]
    plain = ~table["perturbed"].to_numpy(bool)  # perturbed strides are the responses, judged in their window later
    if plain.sum() >= MIN_STRIDES_FOR_OUTLIERS:
        verdict = iqr_outliers(by_stride[plain], whisker, max_fraction, names=joint_names, source=names["angles"])
    else:  # too few to judge: none removed, the trial flagged below
        warnings.warn(
            f"{names['angles']}: {int(plain.sum())} complete unperturbed {side} stride(s) with events from "
            f"{names['events']}; the outlier rule needs at least {MIN_STRIDES_FOR_OUTLIERS}: none judged",
            TooFewStridesWarning,
            stacklevel=2,
        )
        verdict = pd.DataFrame(
            {
                "stride": np.arange(int(plain.sum()), dtype=np.int64),
                **{f"fraction_outlying_{j}": np.nan for j in joint_names},
                "removed": False,
                "reason": "",
            }
        )
    verdict["stride"] = table.loc[plain, "stride"].to_numpy()
    out = table.merge(verdict, on="stride", how="left")
    out["removed"] = out["removed"].fillna(False).astype(bool)
    out.loc[out["perturbed"], "reason"] = "perturbed"
    out["reason"] = out["reason"].fillna("")
    if force_n is not None:
        out = out.merge(_force_metric_columns(t, force_n, table, names["force"]).reset_index(), on="stride")
    n_kept = int((~out["removed"] & ~out["perturbed"]).sum())
    log.info(
        "%s: %d strides, %d perturbed, %d removed as outliers, %d unperturbed kept",
        names["angles"],
        len(out),
        int(out["perturbed"].sum()),
        int(out["removed"].sum()),
        n_kept,
    )
    for r in out[out["removed"]].itertuples():
        log.info("stride %d removed: %s", r.stride, r.reason)
    too_few = not check_enough_strides(n_kept, names["angles"], min_valid)
    cycles = cycles_table(t, values, cols, table, n_points, force_n, names)
    lost = pd.concat(dropped, ignore_index=True)[list(DROPPED_COLUMNS)]
    return StrideTables(out, cycles, too_few, lost)


def _strides_without_ik_gaps(
    table: pd.DataFrame, t: np.ndarray, values: np.ndarray, source: str
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The strides whose joint angles ``values`` (n_frames, 3; rad at ``t`` s) are finite from heel strike to
    end, renumbered, and the others (``heel_strike_s``, ``end_s`` in s, ``reason`` ``ik_frames_left_out``)."""
    # frames left out of IK (too few markers) and angles no marker determined are NaN: such strides cannot be cut
    complete = np.isfinite(values).all(axis=1)
    whole = [bool(complete[(t >= a) & (t <= b)].all()) for a, b in zip(table.heel_strike_s, table.end_s)]
    lost = table.loc[[not w for w in whole], ["heel_strike_s", "end_s"]].assign(reason="ik_frames_left_out")
    if not all(whole):
        log.info("%s: %d stride(s) with frames left out of IK (NaN angles) dropped", source, len(whole) - sum(whole))
        table = table[whole].reset_index(drop=True)
    table["stride"] = np.arange(len(table))
    return table, lost


def _strides_inside_robot_log(
    table: pd.DataFrame, t: np.ndarray, force_n: np.ndarray, n_with_events: int, source: str
) -> tuple[pd.DataFrame, pd.DataFrame | None]:
    """The strides whose force ``force_n`` (n_frames,; N at ``t`` s, NaN outside the robot log) is finite from
    heel strike to end, and the others (``heel_strike_s``, ``end_s``, ``reason`` ``outside_robot_log``; None
    when every stride is inside), with a warning naming the share of the ``n_with_events`` strides lost."""
    covered = np.isfinite(force_n)
    ok = [bool(covered[(t >= a) & (t <= b)].all()) for a, b in zip(table.heel_strike_s, table.end_s)]
    if all(ok):
        return table, None
    lost = table.loc[[not k for k in ok], ["heel_strike_s", "end_s"]]
    span = t[covered]
    log.warning(
        "%s: %d of %d strides with events lie outside the robot log's span (%s of the trial's %.2f .. %.2f s) "
        "and are dropped: is the robot log truncated?",
        source,
        len(lost),
        n_with_events,
        f"{span[0]:.2f} .. {span[-1]:.2f} s" if span.size else "no frame",
        t[0],
        t[-1],
    )
    table = table[ok].reset_index(drop=True)
    table["stride"] = np.arange(len(table))
    return table, lost.assign(reason="outside_robot_log")


def _with_perturbations(table: pd.DataFrame, t: np.ndarray, perturbation: pd.Series | None) -> pd.DataFrame:
    """The stride table with the columns ``perturbed`` and ``onset_s`` (the first perturbation onset in the
    stride, s; NaN if none), from the 0/1 ``perturbation`` flag (n_frames,) at ``t`` (s; None: none perturbed)."""
    table["perturbed"] = False
    table["onset_s"] = np.nan
    if perturbation is not None:
        onsets = perturbation_onsets(t, perturbation.to_numpy(float))
        for i, (a, b) in enumerate(zip(table.heel_strike_s, table.end_s)):
            within = onsets[(onsets >= a) & (onsets < b)]
            if within.size:
                table.loc[i, ["perturbed", "onset_s"]] = (True, within[0])
    return table


def _force_metric_columns(t: np.ndarray, force_n: np.ndarray, table: pd.DataFrame, source: str) -> pd.DataFrame:
    """RMS and largest absolute force (N) per stride (index) and phase (columns ``rms_force_{phase}_n``,
    ``max_abs_force_{phase}_n``) from the force ``force_n`` (n_frames,; NaN outside the robot log) at ``t`` (s)."""
    # samples outside the robot log (NaN) belong to no stride kept above: the metrics need only the others
    logged = np.isfinite(force_n)
    if logged.sum() >= 2 or len(table):
        metrics = force_phase_metrics(t[logged], force_n[logged], table, source=source)
    else:  # no stride and (almost) no robot log: the columns without rows
        metrics = pd.DataFrame(
            {
                "stride": np.empty(0, np.int64),
                "phase": np.empty(0, object),
                "rms_force_n": np.empty(0),
                "max_abs_force_n": np.empty(0),
            }
        )
    wide = metrics.pivot(index="stride", columns="phase", values=["rms_force_n", "max_abs_force_n"])
    wide.columns = [f"{m.removesuffix('_n')}_{ph}_n" for m, ph in wide.columns]
    # the same columns without any stride
    return wide.reindex(columns=[f"{m}_{ph}_n" for m in ("rms_force", "max_abs_force") for ph in FORCE_PHASES])


def _mean_duration_s(table: pd.DataFrame, source: str) -> float:
    """Mean of the ``duration_s`` column (s); NaN without strides (an untyped empty column included)."""
    try:
        duration = table["duration_s"].astype(float)
    except (TypeError, ValueError):
        raise LoperInputError(f"{where(source)}stride table: column 'duration_s' is not numeric") from None
    return float(duration.mean())


def stride_summary(
    tables: Mapping[tuple[str, str], pd.DataFrame],
    min_valid: int = MIN_VALID_STRIDES,
    contacts: Mapping[tuple[str, str], pd.DataFrame] | None = None,
    dropped: Mapping[tuple[str, str], pd.DataFrame] | None = None,
) -> pd.DataFrame:
    """One row per subject x trial: strides found, removed as outliers (and why), kept, and a status.

    ``dropped``: the strides each trial could not cut (:attr:`StrideTables.dropped`); with them, the columns
    ``n_outside_robot_log`` and ``outside_robot_log_fraction`` (of the strides with events), and the status
    ``log_truncated`` where that share exceeds :data:`MAX_OUTSIDE_LOG_FRACTION` (the robot log ends, or starts,
    within the trial).

    ``tables``: ``{(subject, trial): stride table}`` of :func:`stride_tables`.
    ``status`` is ``ok`` or ``too_few_strides`` (fewer than ``min_valid``
    kept: the trial is flagged, not dropped silently). ``contacts``: the
    force-plate contact tables (:func:`loper_analysis.gait.contacts.foot_contacts`,
    column ``flag``) of the same trials; when any trial has one, the column
    ``n_contacts_flagged`` counts the contacts left out of the events for a
    reason (two feet, no foot, off the plate, wrong belt, heel marker missing;
    not the contacts cut by the start or end of the recording). Trials whose
    events came from named GRF channels have an empty table.

    A trial with 0 or 1 strides is a row like any other (``n_strides`` 0 or
    1, ``mean_stride_s`` empty without strides, status ``too_few_strides``
    unless ``min_valid`` allows it). A table read back from its TSV without
    any row holds untyped (object) columns; ``removed`` and ``perturbed`` are
    read as booleans (:func:`loper_analysis.checks.bool_column`) and
    ``duration_s`` as a number in s, so such a table gives the same row as
    the empty table :func:`stride_tables` returned.

    Raises
    ------
    LoperInputError
        A stride table without the columns :data:`SUMMARY_COLUMNS` (naming
        the subject and trial), with a ``removed``/``perturbed`` cell that is
        not a boolean or a ``duration_s`` that is not numeric.
    """
    rows = []
    with_contacts = contacts is not None and any(len(c) for c in contacts.values())
    for (subject, trial), table in tables.items():
        source = f"{subject} {trial}"
        require_columns(table, SUMMARY_COLUMNS, source, "stride table")
        removed_mask = bool_column(table, "removed", source, "stride table")
        removed = table[removed_mask]
        signals = [c.removeprefix("fraction_outlying_") for c in table.columns if c.startswith("fraction_outlying_")]
        reasons = removed["reason"].fillna("").astype(str)  # a column without any reason reads as float
        why = {s: int(reasons.str.contains(f"{s}:").sum()) for s in signals}
        perturbed = (
            bool_column(table, "perturbed", source, "stride table")
            if "perturbed" in table.columns
            else np.zeros(len(table), dtype=bool)
        )
        n_kept = int((~removed_mask & ~perturbed).sum())
        rows.append(
            {
                "subject": subject,
                "trial": trial,
                "n_strides": len(table),
                "n_perturbed": int(perturbed.sum()),
                "n_removed": len(removed),
                "n_kept": n_kept,
                **{f"n_removed_{s}": n for s, n in why.items()},
                "mean_stride_s": _mean_duration_s(table, source),
                "status": "ok" if n_kept >= min_valid else "too_few_strides",
            }
        )
        if dropped is not None:
            lost = dropped[(subject, trial)]
            n_out = int((lost["reason"] == "outside_robot_log").sum()) if len(lost) else 0
            share = n_out / (len(table) + len(lost)) if len(table) + len(lost) else 0.0
            rows[-1]["n_outside_robot_log"] = n_out
            rows[-1]["outside_robot_log_fraction"] = share
            if share > MAX_OUTSIDE_LOG_FRACTION:
                rows[-1]["status"] = "log_truncated"
        if with_contacts:
            from loper_analysis.gait.contacts import count_flagged

            rows[-1]["n_contacts_flagged"] = count_flagged(contacts[(subject, trial)]["flag"])
    return pd.DataFrame(rows)


def phase_cycles(
    cycles: pd.DataFrame,
    strides: pd.DataFrame,
    phase: str,
    columns: Sequence[str],
    keep_removed: bool = False,
    source: str = "cycles",
) -> np.ndarray:
    """Normalised cycles of one phase as (n_strides, n_points, len(columns)).

    Perturbed strides and (unless ``keep_removed``) outliers are left out.
    """
    plain = ~strides["perturbed"].astype(bool) if "perturbed" in strides.columns else True
    keep = strides.loc[plain, "stride"] if keep_removed else strides.loc[~strides["removed"] & plain, "stride"]
    sel = cycles[(cycles["phase"] == phase) & cycles["stride"].isin(keep)]
    n_points = int(sel["point"].max()) + 1 if len(sel) else 0
    require_columns(sel, list(columns), source)
    return sel[list(columns)].to_numpy(float).reshape(-1, n_points, len(columns))
