"""The robot log on the motion-capture clock: forces resampled at the mocap frames, perturbation onsets.

Chain (``docs/processing.md``, :func:`robot_log_frames_and_native`): rising
edges of the log's ``sync_v`` and of the mocap sync channel -> clock map
(:mod:`loper_analysis.device.clock_sync`) -> zero-phase 4th-order 40 Hz
Butterworth of the forces at the robot rate
(:func:`loper_analysis.filtering.lowpass`) -> robot sample times mapped to
the mocap clock -> linear interpolation of the forces, nearest-sample pick of
the perturbation flag, at the mocap frame times (128 Hz); the same filtered
forces at every robot sample, on the mocap clock, for the identification.

Checks guard against records that would give wrong numbers, or a misleading error later
(``docs/device.md``, "Checks on the robot's records"): each sync signal must look like a pulse train
(:func:`loper_analysis.device.clock_sync.require_pulse_train`), the desired force's pulses must be about the
configured perturbation force (:func:`require_pulse_amplitude`: both forces in kN are caught here), the measured
force must be in the unit of the desired one, N (:func:`require_force_unit`), the sync pulses
must have the same high time in both records (an inverted sync, e.g. an
active-low robot output, shifts the clock map by the pulse width;
:func:`loper_analysis.device.clock_sync.clock_map`), and force pulses in the load
cell must carry the perturbation flag (:func:`check_perturbation_flags`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.checks import positive
from loper_analysis.device.clock_sync import ClockMap, clock_map, high_times, require_pulse_train, rising_edges
from loper_analysis.device.pulse import find_force_pulses
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import CUTOFF_HZ, ORDER, lowpass
from loper_analysis.study_design import PULSE_FORCE_N

__all__ = [
    "SYNC_CHANNEL",
    "LoadcellSettings",
    "OUTPUT_COLUMNS",
    "SHANK_OUTPUT_COLUMNS",
    "MIN_UNFLAGGED_PULSES",
    "FORCE_RATIO_RANGE",
    "PULSE_AMPLITUDE_RANGE",
    "require_force_unit",
    "require_pulse_amplitude",
    "robot_log_frames_and_native",
    "check_shank_rod",
    "check_perturbation_flags",
    "perturbation_onsets",
]

log = logging.getLogger(__name__)

#: Analog channel of the robot's sync output in the C3D (config ``events.sync_channel``).
SYNC_CHANNEL: str = "sync"


@dataclass(frozen=True)
class LoadcellSettings:
    """The robot log on the mocap clock: the C3D's ``sync_channel``, the forces' low-pass (``cutoff_hz`` Hz,
    Butterworth of ``order``, run forward and backward; config ``events.sync_channel``, ``markers.filter.*``) and the
    study's perturbation force ``pulse_force_n`` (N; config ``planning.pulse_force_n``), which the desired force's
    pulses are checked against (:func:`require_pulse_amplitude`), and a second rod's at the shank
    ``shank_pulse_force_n`` (N; ``planning.shank_pulse_force_n``; 0: the logs hold no shank pulses)."""

    sync_channel: str = SYNC_CHANNEL
    cutoff_hz: float = CUTOFF_HZ
    order: int = ORDER
    pulse_force_n: float = PULSE_FORCE_N
    shank_pulse_force_n: float = 0.0


#: Columns of both tables of :func:`robot_log_frames_and_native`, in order ...
OUTPUT_COLUMNS: tuple[str, ...] = ("time_s", "force_measured_n", "force_desired_n", "perturbation")
#: ... and after them, from a log with a second rod at the shank, its load cell's forces (N).
SHANK_OUTPUT_COLUMNS: tuple[str, ...] = ("shank_force_measured_n", "shank_force_desired_n")
#: The config key that says whether the logs hold a second rod's pulses.
SHANK_PULSE_KEY = "planning.shank_pulse_force_n"

_LOG_COLUMNS = ("time_s", "force_desired_n", "force_measured_n", "sync_v", "perturbation")
_FORCE_COLUMNS = ("force_measured_n", "force_desired_n")

#: A log is refused when at least this many force pulses are found and more than half of them carry no flag.
MIN_UNFLAGGED_PULSES = 3
#: Accepted range of the measured over the desired force during the flagged pulses: outside, a unit (kN, mV).
FORCE_RATIO_RANGE: tuple[float, float] = (0.5, 2.0)
#: Smallest peak desired force during the flagged samples (N) for that ratio to be judged (a log without the
#: desired pulses cannot be).
MIN_DESIRED_PULSE_N: float = 1.0
#: Accepted range of the desired pulses' amplitude over the configured perturbation force: outside, a unit (kN
#: gives 0.001, mN 1000) or a log of another protocol. A decade either way: the study's pulses vary far less.
PULSE_AMPLITUDE_RANGE: tuple[float, float] = (0.1, 10.0)
#: A force pulse counts as flagged if the flag is 1 anywhere from this long before its start to this long after
#: its end, s (the load cell follows the flag by the robot's delays, ~15 ms).
_FLAG_MARGIN_S = 0.1


def robot_log_frames_and_native(
    log: pd.DataFrame,
    log_rate_hz: float,
    mocap_sync_v,
    analog_rate_hz: float,
    frame_time_s,
    *,
    cutoff_hz: float = CUTOFF_HZ,
    order: int = ORDER,
    source: str = "",
    analog_start_s: float | None = None,
    max_drift: float = 1e-3,
    tolerance_s: float = 3e-3,
    sync_channel: str = "",
    pulse_force_n: float | None = None,
    shank_pulse_force_n: float | None = None,
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The robot log's forces and perturbation flag on the motion-capture frames, and the same forces at the robot
    log's own samples.

    1. Both sync signals must look like pulse trains
       (:func:`loper_analysis.device.clock_sync.require_pulse_train`); then the
       clock map (:func:`loper_analysis.device.clock_sync.clock_map`) from the rising edges of the log's
       ``sync_v`` (robot clock: ``time_s`` at the interpolated sample index)
       and of ``mocap_sync_v`` (mocap clock: ``analog_start_s + index /
       analog_rate_hz``); the pulses' high times
       (:func:`loper_analysis.device.clock_sync.high_times`) must agree between the
       two (same polarity).
    2. ``force_measured_n`` and ``force_desired_n`` low-passed at the robot
       rate (:func:`~loper_analysis.filtering.lowpass`: zero-phase
       Butterworth, ``order``, ``cutoff_hz``) before resampling.
    3. Robot sample times mapped to the mocap clock; forces linearly
       interpolated at ``frame_time_s``; ``perturbation`` taken from the
       nearest robot sample (never interpolated), so a flag's onset lands
       within one mocap frame (plus half a robot sample) of its mapped time.
    4. The desired pulses must be about ``pulse_force_n`` (:func:`require_pulse_amplitude`), the measured
       force in the desired one's unit (:func:`require_force_unit`), and force pulses in the low-passed
       ``force_measured_n`` must carry the ``perturbation`` flag (:func:`check_perturbation_flags`).

    The robot rate keeps the pulse's edges, which the 128 Hz frames cut
    short: the fit takes its force from the second table
    (:func:`loper_analysis.impedance.identification.prepare_window`, ``force_time_s``).

    Gap policy: frames outside the robot log's mapped span (first to last
    sample) get NaN in every column but ``time_s``, which is why
    ``perturbation`` is float (0.0 / 1.0 / NaN). The filter's start-up
    transients (odd-extension padding) affect the first and last ~0.1 s of
    the log; NaN ``sync_v`` samples only cost the edges they hide.

    Parameters
    ----------
    log : pandas.DataFrame
        Robot log (:mod:`loper_analysis.io.robot_log`), at least the columns
        ``time_s`` (s, robot clock), ``force_desired_n``, ``force_measured_n``
        (N, finite), ``sync_v`` (V, NaN = missing) and ``perturbation`` (0/1).
    log_rate_hz : float
        Robot log rate, Hz (1000).
    mocap_sync_v : array_like, shape (n_analog,)
        The mocap analog channel recording the robot's sync output, V.
    analog_rate_hz : float
        Mocap analog rate, Hz (1024).
    frame_time_s : array_like, shape (n_frames,)
        Mocap frame times, s, strictly increasing (128 Hz).
    cutoff_hz, order : float, int
        Force low-pass (the study's: 40 Hz, 4th order).
    source : str
        Names the files in error messages.
    analog_start_s : float, optional
        Mocap time of analog sample 0, s; default ``frame_time_s[0]`` (C3D:
        analog and point data start together).
    max_drift, tolerance_s : float
        Passed to :func:`loper_analysis.device.clock_sync.clock_map`.
    sync_channel : str
        Name of the mocap sync channel, for messages.
    pulse_force_n : float, optional
        The configured perturbation force, N (config ``planning.pulse_force_n``); None: the desired pulses'
        amplitude is not checked.
    shank_pulse_force_n : float, optional
        A second rod's configured pulse at the shank, N (``planning.shank_pulse_force_n``): above 0 the log
        must hold that rod's load cell (``shank_force_desired_n``, ``shank_force_measured_n``) with pulses
        about this size; 0: the log must hold no shank pulses. None: not checked. A log with the shank
        columns gives their low-passed forces in both tables (:data:`SHANK_OUTPUT_COLUMNS`).

    Returns
    -------
    frames : pandas.DataFrame, shape (n_frames, 4), or (n_frames, 6) with a shank rod
        Columns :data:`OUTPUT_COLUMNS` (then :data:`SHANK_OUTPUT_COLUMNS`): ``time_s`` (s, mocap clock, =
        ``frame_time_s``), ``force_measured_n``, ``force_desired_n`` (N),
        ``perturbation`` (0.0/1.0, NaN outside the log). ``attrs["clock_map"]``
        holds the :class:`loper_analysis.device.clock_sync.ClockMap`.
    native : pandas.DataFrame, shape (n_samples, 4) or (n_samples, 6)
        The same columns at every robot sample (``log_rate_hz``): ``time_s``
        the sample's time mapped to the mocap clock (s), the low-passed forces
        (N) and the flag (0.0/1.0).

    Raises
    ------
    LoperInputError
        Missing columns, a ``time_s`` step inconsistent with ``log_rate_hz``,
        non-finite forces or frame times, an all-NaN or flat sync signal in
        either record, a sync signal that is no pulse train (noise:
        :func:`loper_analysis.device.clock_sync.require_pulse_train`), a clock map refused by
        :func:`loper_analysis.device.clock_sync.clock_map` (also: sync pulses whose high times disagree between
        the records, e.g. an inverted robot sync), no frame
        inside the log's span, desired pulses far from ``pulse_force_n`` (:func:`require_pulse_amplitude`: both
        forces in kN), a measured force in another unit (:func:`require_force_unit`), force pulses without
        perturbation flags (:func:`check_perturbation_flags`); a second rod configured without its columns, or
        shank pulses in a log whose design has none (:func:`check_shank_rod`).
    """
    src = source or "robot log"
    if not isinstance(log, pd.DataFrame):
        raise LoperInputError(f"{src}: log must be a pandas DataFrame, got {type(log).__name__}")
    missing = [c for c in _LOG_COLUMNS if c not in log.columns]
    if missing:
        raise LoperInputError(f"{src}: robot log lacks column(s) {', '.join(missing)}")
    rate = positive("log_rate_hz", log_rate_hz, src)
    arate = positive("analog_rate_hz", analog_rate_hz, src)
    t_log = _log_times(log, rate, src)
    frames = np.asarray(frame_time_s, dtype=float)
    if frames.ndim != 1 or frames.size == 0 or not np.all(np.isfinite(frames)) or np.any(np.diff(frames) <= 0):
        raise LoperInputError(f"{src}: frame_time_s must be a non-empty, finite, strictly increasing 1-D array")
    start = frames[0] if analog_start_s is None else float(analog_start_s)

    cm = _sync_clock_map(
        log, t_log, rate, (mocap_sync_v, arate, start), src, sync_channel, max_drift=max_drift, tolerance_s=tolerance_s
    )
    t_mapped = cm.to_mocap(t_log)
    inside = (frames >= t_mapped[0]) & (frames <= t_mapped[-1])
    if not inside.any():
        raise LoperInputError(
            f"{src}: no mocap frame ({frames[0]:.6g} .. {frames[-1]:.6g} s) lies within the robot log's span on "
            f"the mocap clock ({t_mapped[0]:.6g} .. {t_mapped[-1]:.6g} s)"
        )
    shank = check_shank_rod(log, shank_pulse_force_n, src)
    columns = (*OUTPUT_COLUMNS, *(SHANK_OUTPUT_COLUMNS if shank else ()))
    native = {"time_s": t_mapped, **_filtered_forces(log, rate, cutoff_hz, order, src, shank)}
    out = {"time_s": frames}
    for col in (c for c in columns if c in native and c != "time_s"):
        out[col] = np.interp(frames, t_mapped, native[col], left=np.nan, right=np.nan)
    flag = _perturbation_flag(log, src)
    if pulse_force_n is not None:
        require_pulse_amplitude(log["force_desired_n"].to_numpy(dtype=float), flag, pulse_force_n, src)
    require_force_unit(native["force_desired_n"], native["force_measured_n"], flag, src)
    if shank and shank_pulse_force_n:
        require_pulse_amplitude(
            log["shank_force_desired_n"].to_numpy(dtype=float), flag, shank_pulse_force_n, src, "shank_force_desired_n"
        )
        require_force_unit(native["shank_force_desired_n"], native["shank_force_measured_n"], flag, src, "shank_force_")
    check_perturbation_flags(native["force_measured_n"], flag, rate, t_log, src)
    pos = np.clip(np.searchsorted(t_mapped, frames), 1, t_mapped.size - 1)
    nearest = np.where(frames - t_mapped[pos - 1] <= t_mapped[pos] - frames, pos - 1, pos)
    out["perturbation"] = np.where(inside, flag[nearest], np.nan)
    native["perturbation"] = flag
    result = pd.DataFrame(out, columns=list(columns))
    result.attrs["clock_map"] = cm
    return result, pd.DataFrame(native, columns=list(columns))


def check_shank_rod(log: pd.DataFrame, shank_pulse_force_n: float | None, source: str = "") -> bool:
    """Whether the robot log holds a second rod's load cell at the shank, checked against the design.

    ``shank_pulse_force_n`` (N; ``planning.shank_pulse_force_n``): above 0 the log must hold both
    ``shank_force_desired_n`` and ``shank_force_measured_n``; 0 (the thigh rod alone) its desired shank force, if
    any, must stay below :data:`MIN_DESIRED_PULSE_N` (a rod attached but not pushed); None: not checked.

    Raises
    ------
    LoperInputError
        One shank column without the other; a second rod configured without its columns; shank pulses in a log
        whose design has none. Each names the file, the columns and ``planning.shank_pulse_force_n``.
    """
    src = source or "robot log"
    present = [c for c in ("shank_force_desired_n", "shank_force_measured_n") if c in log.columns]
    if len(present) == 1:
        raise LoperInputError(
            f"{src}: robot log holds {present[0]} without its pair; a second rod's load cell needs both "
            "shank_force_desired_n and shank_force_measured_n (N)"
        )
    if shank_pulse_force_n is None:
        return bool(present)
    if shank_pulse_force_n and not present:
        raise LoperInputError(
            f"{src}: {SHANK_PULSE_KEY} = {shank_pulse_force_n:g} N plans a second rod at the shank, but the robot log "
            "holds no shank_force_desired_n and shank_force_measured_n columns (its load cell); record them, or set "
            f"{SHANK_PULSE_KEY} to 0 for the thigh rod alone"
        )
    if present and not shank_pulse_force_n:
        desired = log["shank_force_desired_n"].to_numpy(dtype=float, na_value=np.nan)
        peak = float(np.nanmax(np.abs(desired))) if desired.size else 0.0
        if peak >= MIN_DESIRED_PULSE_N:
            raise LoperInputError(
                f"{src}: the robot log's column 'shank_force_desired_n' pulses to {peak:.4g} N, but "
                f"{SHANK_PULSE_KEY} is 0 (the thigh rod alone): set it to the shank rod's planned pulse (N)"
            )
    return bool(present)


def _log_times(log: pd.DataFrame, rate: float, src: str) -> np.ndarray:
    """The log's ``time_s`` (s, robot clock, shape (n_samples,)), checked: at least 2 finite samples, each step
    ``1 / rate`` within 1 %."""
    t_log = log["time_s"].to_numpy(dtype=float)
    if t_log.size < 2 or not np.all(np.isfinite(t_log)):
        raise LoperInputError(f"{src}: column 'time_s' must hold >= 2 finite samples")
    step = np.diff(t_log)
    bad = np.flatnonzero(np.abs(step * rate - 1.0) > 0.01)
    if bad.size:
        k = int(bad[0]) + 1
        raise LoperInputError(
            f"{src}: column 'time_s', sample {k} (t = {t_log[k]:.9g} s): step {step[k - 1]:.6g} s is not "
            f"1 / log_rate_hz = {1 / rate:.6g} s within 1 %"
        )
    return t_log


def _sync_clock_map(
    log: pd.DataFrame,
    t_log: np.ndarray,
    rate: float,
    mocap_sync: tuple,
    src: str,
    sync_channel: str,
    *,
    max_drift: float,
    tolerance_s: float,
) -> ClockMap:
    """The robot -> mocap clock map (:func:`loper_analysis.device.clock_sync.clock_map`) from the rising edges
    and high times of the log's ``sync_v`` (at ``t_log``, s; ``rate`` Hz) and of the mocap sync channel
    (``mocap_sync``: the channel in V, its rate in Hz and the mocap time of its sample 0 in s)."""
    mocap_sync_v, arate, start = mocap_sync
    robot_name = "robot log column 'sync_v'"
    mocap_name = f"mocap sync channel '{sync_channel}'" if sync_channel else "mocap sync channel"
    robot_sync = log["sync_v"].to_numpy(dtype=float, na_value=np.nan)
    require_pulse_train(robot_sync, rate, source=f"{src}: {robot_name}")
    require_pulse_train(mocap_sync_v, arate, source=f"{src}: {mocap_name}")
    robot_rel = rising_edges(robot_sync, rate, source=f"{src}: {robot_name}")
    mocap_rel = rising_edges(mocap_sync_v, arate, source=f"{src}: {mocap_name}")
    robot_edges = np.interp(robot_rel * rate, np.arange(t_log.size), t_log)
    return clock_map(
        robot_edges,
        start + mocap_rel,
        max_drift=max_drift,
        source=src,
        tolerance_s=tolerance_s,
        robot_high_s=high_times(robot_sync, rate, robot_rel),
        mocap_high_s=high_times(mocap_sync_v, arate, mocap_rel),
        robot_name=robot_name,
        mocap_name=mocap_name,
    )


def _filtered_forces(
    log: pd.DataFrame, rate: float, cutoff_hz: float, order: int, src: str, shank: bool = False
) -> dict[str, np.ndarray]:
    """The log's measured and desired forces (N, shape (n_samples,)), with ``shank`` the shank rod's too,
    low-passed at the robot rate ``rate`` (Hz; :func:`loper_analysis.filtering.lowpass`), by column."""
    forces = {}
    for col in (*_FORCE_COLUMNS, *(SHANK_OUTPUT_COLUMNS if shank else ())):
        f = log[col].to_numpy(dtype=float, na_value=np.nan)
        try:
            f = lowpass(f, rate, cutoff_hz, order)
        except LoperInputError as exc:
            raise LoperInputError(f"{src}: column '{col}': {exc}") from None
        forces[col] = f
    return forces


def _perturbation_flag(log: pd.DataFrame, src: str) -> np.ndarray:
    """The log's ``perturbation`` column as float (shape (n_samples,)), checked to hold 0 and 1 only."""
    flag = log["perturbation"].to_numpy(dtype=float, na_value=np.nan)
    if not np.all(np.isin(flag, (0.0, 1.0))):
        k = int(np.flatnonzero(~np.isin(flag, (0.0, 1.0)))[0])
        raise LoperInputError(f"{src}: column 'perturbation', sample {k}: value {flag[k]!r} is not 0 or 1")
    return flag


def require_pulse_amplitude(
    desired_n, flag, pulse_force_n: float, source: str = "", column: str = "force_desired_n"
) -> float:
    """Refuse a robot log whose desired perturbation pulses are far from the configured perturbation force.

    The amplitude of the desired pulses is the median ``|desired_n|`` over the flagged samples where it exceeds
    half its largest magnitude there (the pulses' plateau). Its ratio to ``|pulse_force_n|`` must lie within
    :data:`PULSE_AMPLITUDE_RANGE` (0.1 .. 10). A log in kN gives about 0.001: with both force columns in kN,
    :func:`require_force_unit` sees a ratio of 1 and the fit would fail later on its VAF without naming the
    force. Logs without flagged samples (minimal-impedance trials) or whose desired force is zero throughout them
    (no desired pulses logged) cannot be judged and pass.

    Parameters
    ----------
    desired_n : array_like, shape (n,)
        The log's ``force_desired_n`` as logged (N).
    flag : array_like, shape (n,)
        The log's ``perturbation`` column, 0/1.
    pulse_force_n : float
        The configured perturbation force, N (config ``planning.pulse_force_n``; its sign is the direction).
    source : str
        Names the robot log in messages.
    column : str
        The column ``desired_n`` is (``force_desired_n``, or the shank rod's ``shank_force_desired_n``, whose
        configured force is ``planning.shank_pulse_force_n``), named in messages.

    Returns
    -------
    float
        The ratio of the pulses' amplitude to ``|pulse_force_n|`` (NaN when not judged).

    Raises
    ------
    LoperInputError
        A ratio outside :data:`PULSE_AMPLITUDE_RANGE`, naming the file, the column, the measured amplitude, the
        configured force and the likely cause (kN, mN); a zero or non-finite ``pulse_force_n``.
    """
    src = source or "robot log"
    key = SHANK_PULSE_KEY if column.startswith("shank_") else "planning.pulse_force_n"
    configured = abs(float(pulse_force_n))
    if not (math.isfinite(configured) and configured > 0):
        raise LoperInputError(f"{src}: pulse_force_n must be a finite non-zero force (N), got {pulse_force_n!r}")
    fd = np.abs(np.asarray(desired_n, float))
    on = (np.asarray(flag, float) == 1) & np.isfinite(fd)
    if not on.any() or not np.max(fd[on]) > 0:
        return float("nan")
    strong = on & (fd > 0.5 * np.max(fd[on]))
    amplitude = float(np.median(fd[strong]))
    ratio = amplitude / configured
    lo, hi = PULSE_AMPLITUDE_RANGE
    if lo <= ratio <= hi:
        return ratio
    if 0.0003 < ratio < 0.003:
        cause = "the log's forces look like kN instead of N (ratio about 0.001)"
    elif 300 < ratio < 3000:
        cause = "the log's forces look like mN instead of N (ratio about 1000)"
    else:
        cause = "a force in another unit, or a log of another protocol"
    raise LoperInputError(
        f"{src}: column '{column}': the perturbation pulses reach {amplitude:.4g} (median over the "
        f"{int(strong.sum())} flagged samples of their plateau), {ratio:.4g} times the configured perturbation "
        f"force of {configured:g} N ({key}; accepted {lo:g} .. {hi:g} times): {cause}. Both force "
        f"columns, {column} and {column.replace('desired', 'measured')}, must hold newtons"
    )


def require_force_unit(desired_n, measured_n, flag, source: str = "", prefix: str = "force_") -> float:
    """Refuse a robot log whose measured force is not in the desired force's unit (N).

    During the flagged perturbation pulses the load cell measures about the force the controller asks for: the
    median ratio of ``measured_n`` to ``desired_n`` over the flagged samples where the desired force exceeds half
    its largest magnitude lies within :data:`FORCE_RATIO_RANGE`. A load cell logged in kN gives about 0.001, an
    uncalibrated one in mV a ratio far from 1. Logs without flagged pulses (minimal-impedance trials), or whose
    desired force stays below :data:`MIN_DESIRED_PULSE_N` during them, cannot be judged and pass.

    Parameters
    ----------
    desired_n, measured_n : array_like, shape (n,)
        The log's ``force_desired_n`` and ``force_measured_n`` (low-passed).
    flag : array_like, shape (n,)
        The log's ``perturbation`` column, 0/1.
    source : str
        Names the robot log in messages.
    prefix : str
        The columns' prefix (``force_``, or ``shank_force_`` for a second rod's load cell), named in messages.

    Returns
    -------
    float
        The median ratio (NaN when not judged).

    Raises
    ------
    LoperInputError
        A ratio outside :data:`FORCE_RATIO_RANGE`, naming the file, the columns, the ratio and the likely unit.
    """
    fd = np.asarray(desired_n, float)
    fm = np.asarray(measured_n, float)
    on = (np.asarray(flag, float) == 1) & np.isfinite(fd) & np.isfinite(fm)
    if not on.any() or not np.nanmax(np.abs(fd[on])) >= MIN_DESIRED_PULSE_N:
        return float("nan")
    strong = on & (np.abs(fd) > 0.5 * np.nanmax(np.abs(fd[on])))
    ratio = float(np.median(fm[strong] / fd[strong]))
    lo, hi = FORCE_RATIO_RANGE
    if lo <= ratio <= hi:
        return ratio
    unit = (
        "in kN (ratio about 0.001)"
        if 0.0003 < abs(ratio) < 0.003
        else "uncalibrated (a voltage, in mV or V), or in another unit"
    )
    raise LoperInputError(
        f"{source or 'robot log'}: column '{prefix}measured_n' is {ratio:.4g} times column '{prefix}desired_n' during "
        f"the {int(strong.sum())} samples of the flagged perturbation pulses (median; accepted {lo:g} .. {hi:g}): "
        f"is the load cell logged {unit}? Both columns must hold newtons"
    )


def check_perturbation_flags(force_n, flag, sample_rate_hz: float, time_s, source: str = "") -> np.ndarray:
    """Refuse a robot log whose force shows perturbation pulses that its perturbation flag does not mark.

    Pulses are found in the force itself (:func:`loper_analysis.device.pulse.find_force_pulses`);
    a pulse is flagged if ``flag`` is 1 anywhere within ``_FLAG_MARGIN_S``
    (0.1 s) of it. A log with at least :data:`MIN_UNFLAGGED_PULSES` pulses of
    which more than half are unflagged is refused: its strides could not be
    sorted into perturbed and unperturbed ones (a perturbation trial would end
    as ``too_few_strides`` with no error). Fewer unflagged pulses are logged as
    a warning. Logs without pulses (minimal-impedance trials) pass.

    Parameters
    ----------
    force_n : array_like, shape (n,)
        Measured interaction force at the robot rate, N (low-passed).
    flag : array_like, shape (n,)
        The log's ``perturbation`` column, 0/1.
    sample_rate_hz : float
        Robot log rate, Hz.
    time_s : array_like, shape (n,)
        The log's ``time_s`` (robot clock), s: the times named in messages.
    source : str
        Names the robot log in messages.

    Returns
    -------
    numpy.ndarray, shape (n_pulses, 3)
        The pulses found (:func:`loper_analysis.device.pulse.find_force_pulses`).

    Raises
    ------
    LoperInputError
        Too many unflagged pulses: names the file, the columns ``perturbation``
        and ``force_measured_n``, the number of flagged pulses in the log, the
        number of force pulses and the robot-clock times of the first
        unflagged ones.
    """
    src = source or "robot log"
    rate = positive("sample_rate_hz", sample_rate_hz, src)
    f = np.asarray(flag, dtype=float)
    t = np.asarray(time_s, dtype=float)
    pulses = find_force_pulses(force_n, rate, source=f"{src}: column 'force_measured_n'")
    if not len(pulses):
        return pulses
    on = f == 1
    n_flags = int(on[0]) + int(np.sum(~on[:-1] & on[1:]))
    margin = int(round(_FLAG_MARGIN_S * rate))
    cum = np.concatenate(([0], np.cumsum(on)))
    a = np.clip(pulses[:, 0].astype(int) - margin, 0, f.size)
    b = np.clip(pulses[:, 1].astype(int) + margin, 0, f.size)
    unflagged = cum[b] - cum[a] == 0
    n_pulses, n_unflagged = len(pulses), int(unflagged.sum())
    if not n_unflagged:
        return pulses
    first = pulses[unflagged, 0].astype(int)
    times = ", ".join(f"{t[k]:.3f}" for k in first[:5]) + (", ..." if first.size > 5 else "")
    peak = float(np.median(np.abs(pulses[:, 2])))
    width_ms = float(np.median(pulses[:, 1] - pulses[:, 0])) / rate * 1e3
    seen = (
        f"column 'perturbation' flags {n_flags} pulse(s), but column 'force_measured_n' shows {n_pulses} force "
        f"pulse(s) (median peak {peak:.0f} N, {width_ms:.0f} ms), {n_unflagged} of them without a flag, at "
        f"t = {times} s (robot clock)"
    )
    if n_pulses >= MIN_UNFLAGGED_PULSES and 2 * n_unflagged > n_pulses:
        what = (
            "the log has no perturbation flags, so no stride would count as perturbed"
            if not n_flags
            else "most pulses lack their perturbation flag, so their strides would count as unperturbed"
        )
        raise LoperInputError(
            f"{src}: {seen}: {what}; check the robot's flag channel (a .mat export: device.mat_column_map.perturbation)"
        )
    log.warning("%s: %s: their strides count as unperturbed", src, seen)
    return pulses


def perturbation_onsets(time_s, flag) -> np.ndarray:
    """Times of the 0 -> 1 transitions of a perturbation flag.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Sample times, s.
    flag : array_like, shape (n,)
        0/1 flag; NaN samples (e.g. outside the robot log) never start an
        onset, nor does a flag already 1 at the first sample.

    Returns
    -------
    numpy.ndarray, shape (n_onsets,)
        ``time_s`` of each first sample at 1 after a sample at 0, s.
    """
    t = np.asarray(time_s, dtype=float)
    f = np.asarray(flag, dtype=float)
    if t.ndim != 1 or f.shape != t.shape:
        raise LoperInputError(f"time_s and flag must be 1-D of equal length, got shapes {t.shape} and {f.shape}")
    bad = ~(np.isnan(f) | np.isin(f, (0.0, 1.0)))
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        raise LoperInputError(f"flag, sample {k}: value {f[k]!r} is not 0, 1 or NaN")
    return t[1:][(f[:-1] == 0) & (f[1:] == 1)]
