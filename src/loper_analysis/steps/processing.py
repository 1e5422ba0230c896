"""File steps of the processing chain: raw C3D and robot log to markers, events, forces and strides.

Chain: raw C3D -> :func:`markers` (gap fill, lab -> model frame, zero-phase
low-pass, TRC) -> (model and IK: :mod:`.model`, :mod:`.ik`) ->
:func:`events` (GRF) -> :func:`loadcell` (robot log on the mocap clock) ->
:func:`strides` (strides, IQR outliers, cycles) -> :func:`strides_summary`.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence

import pandas as pd

from ..constants import SIDES
from ..errors import LoperInputError
from ..io.atomic import PathLike, write_tsv
from ..io.readers import read_tsv

__all__ = ["markers", "events", "loadcell", "strides", "strides_summary"]

log = logging.getLogger(__name__)


def markers(c3d_path: PathLike, trc_out: PathLike, gaps_out: PathLike | None = None,
            rotation_deg: Sequence[float] = (-90.0, 0.0, 0.0), max_gap_frames: int = 10, cutoff_hz: float = 40.0,
            order: int = 4, duration_s: float | None = None) -> pd.DataFrame:
    """C3D markers -> gap fill -> lab-to-model rotation -> zero-phase low-pass -> TRC (mm).

    ``duration_s`` keeps only the first part of the trial (static trials).
    Returns the table of filled gaps (written to ``gaps_out`` when given).
    """
    from ..filtering import lowpass
    from ..io.c3d import read_c3d
    from ..io.opensim_tables import write_trc
    from ..markers import fill_gaps, rotate_markers

    rec = read_c3d(c3d_path)
    time_s, X = rec.time_s, rec.markers_m
    if duration_s is not None:
        keep = time_s < time_s[0] + duration_s - 1e-9
        time_s, X = time_s[keep], X[keep]
    filled, gaps = fill_gaps(X, max_gap_frames, rec.marker_labels, source=str(c3d_path))
    X = rotate_markers(filled, rotation_deg)
    try:
        X = lowpass(X, rec.point_rate_hz, cutoff_hz, order, axis=0)
    except LoperInputError as exc:
        raise LoperInputError(f"{c3d_path}: markers: {exc}") from None
    log.info("%s: %d frames at %g Hz, %d markers, %d gap(s) filled", c3d_path, len(time_s), rec.point_rate_hz,
             len(rec.marker_labels), len(gaps))
    write_trc(trc_out, time_s, X, rec.marker_labels)
    if gaps_out is not None:
        write_tsv(gaps, gaps_out)
    log.info("filled gaps:\n%s", gaps.to_string(index=False))
    return gaps


def events(c3d_path: PathLike, out_tsv: PathLike, grf_channels: Mapping[str, str], threshold_on_n: float = 50.0,
           threshold_off_n: float = 20.0, min_stance_s: float = 0.2, min_swing_s: float = 0.2,
           cutoff_hz: float | None = None, order: int = 4) -> pd.DataFrame:
    """Heel strikes and toe-offs of both legs from the belts' vertical GRF, on the mocap clock.

    ``cutoff_hz`` low-passes the GRF first (zero-phase Butterworth); None
    thresholds the raw force (the hysteresis rejects noise, and a filter would
    smear the unloading at toe-off: 40 Hz moves a 20 N toe-off threshold by
    about 4.5 ms).
    """
    from ..events import gait_events
    from ..filtering import lowpass
    from ..io.c3d import read_c3d

    rec = read_c3d(c3d_path)
    tables = []
    for side in SIDES:
        fz = rec.analog(grf_channels[side])
        if cutoff_hz is not None:
            fz = lowpass(fz, rec.analog_rate_hz, cutoff_hz, order)
        tables.append(gait_events(rec.analog_time_s, fz, side, threshold_on_n, threshold_off_n, min_stance_s,
                                  min_swing_s, source=f"{c3d_path} ({grf_channels[side]})"))
    table = pd.concat(tables, ignore_index=True).sort_values(["time_s", "side"], kind="stable", ignore_index=True)
    write_tsv(table, out_tsv)
    log.info("events per side and kind:\n%s", table.groupby(["side", "event"]).size().to_string())
    return table


def loadcell(c3d_path: PathLike, log_path: PathLike, out_tsv: PathLike, sync_channel: str = "sync", cutoff_hz: float = 40.0,
             order: int = 4) -> pd.DataFrame:
    """The robot log's forces on the mocap frames (sync-pulse clock map, 40 Hz low-pass, 128 Hz)."""
    from ..io.c3d import read_c3d
    from ..io.robot_log import read_robot_log
    from ..loadcell import robot_log_on_mocap_frames

    rec = read_c3d(c3d_path)
    frame, meta = read_robot_log(log_path)
    rate = float(meta["sample_rate_hz"])
    out = robot_log_on_mocap_frames(frame, rate, rec.analog(sync_channel), rec.analog_rate_hz, rec.time_s,
                                    cutoff_hz=cutoff_hz, order=order, source=f"{log_path} / {c3d_path}")
    cm = out.attrs.get("clock_map")
    if cm is not None:
        log.info("%s: clock map %s", log_path, cm)
    write_tsv(out, out_tsv)
    log.info("%d frames on the mocap clock", len(out))
    return out


def strides(angles_tsv: PathLike, events_tsv: PathLike, strides_out: PathLike, cycles_out: PathLike, force_tsv: PathLike | None = None,
            side: str = "left", n_points: int = 101, whisker: float = 1.5, max_fraction: float = 0.2,
            min_valid: int = 5):
    """Strides of one leg, their outlier verdicts and the time-normalised cycles of one trial.

    Writes the stride table and the cycles (:func:`loper_analysis.strides.stride_tables`);
    returns the :class:`~loper_analysis.strides.StrideTables`.
    """
    from ..strides import stride_tables

    sources = {"angles": str(angles_tsv), "events": str(events_tsv), "force": str(force_tsv)}
    force = None if force_tsv is None else read_tsv(force_tsv, "force table", ("time_s", "force_measured_n"))
    tables = stride_tables(read_tsv(angles_tsv, "angle table"), read_tsv(events_tsv, "event table"), force, side,
                           n_points, whisker, max_fraction, min_valid, sources)
    write_tsv(tables.cycles, cycles_out)
    write_tsv(tables.strides, strides_out)
    s = tables.strides
    log.info("%d strides, %d kept", len(s), int((~s["removed"]).sum()))
    return tables


def strides_summary(subject_trials: Sequence[tuple[str, str]], strides_tsvs: Sequence[PathLike], out_tsv: PathLike,
                    min_valid: int = 5) -> pd.DataFrame:
    """One row per subject x trial of the stride tables (:func:`loper_analysis.strides.stride_summary`).

    ``strides_tsvs`` holds one stride table per ``(subject, trial)`` of ``subject_trials``, in order.
    """
    from ..strides import stride_summary

    tables = {tuple(key): read_tsv(path, "stride table", keep_default_na=False, na_values=[""])
              for key, path in zip(subject_trials, strides_tsvs, strict=True)}
    table = stride_summary(tables, min_valid)
    write_tsv(table, out_tsv)
    for row in table[table.status != "ok"].itertuples():
        log.warning("%s %s: only %d valid strides (minimum %d)", row.subject, row.trial, row.n_kept, min_valid)
    log.info("strides:\n%s", table.to_string(index=False))
    return table
