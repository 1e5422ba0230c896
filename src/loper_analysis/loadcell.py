"""The robot log on the motion-capture clock: sync pulses, clock map, resampled forces.

The robot (LOPER) logs at 1000 Hz on its own clock
(:mod:`loper_analysis.io.robot_log`); the motion-capture system records
markers at 128 Hz and analogs at 1024 Hz, one analog channel of which is the
robot's sync output (V). The two clocks differ by an offset (recording starts
seconds apart, either sign) and a small drift (up to a few hundred ppm)::

    t_mocap = offset_s + scale * t_robot

Both are found from the rising edges of the sync signal as seen by both
records (:func:`clock_map`). A pulse train with a fixed period cannot resolve
an offset of whole periods, so walking trials use a train whose pulse-start
intervals are drawn at random (:func:`sync_pulse_train`): a window of a few
consecutive intervals then occurs once only.

Chain (DESIGN.md section 4, :func:`robot_log_on_mocap_frames`): rising edges
of the log's ``sync_v`` and of the mocap sync channel -> clock map ->
zero-phase 4th-order 40 Hz Butterworth of the forces at the robot rate
(:func:`loper_analysis.filtering.lowpass`) -> robot sample times mapped to the
mocap clock -> linear interpolation of the forces, nearest-sample pick of the
perturbation flag, at the mocap frame times (128 Hz).

Edge-time convention: an edge is placed where the straight line between the
last sample below and the first sample at or above the threshold crosses it,
so a sharp step sampled at rate f_s is located to within +-0.5 / f_s, without
bias when the step falls at a random instant between samples (how both
:func:`sync_pulse_train` and the mocap analog input see it). A robot whose
sync output is a zero-order hold updated at its own samples would shift every
robot edge by a constant half robot sample (0.5 ms at 1000 Hz), i.e. the
offset by 0.5 ms: far below one mocap frame (7.8 ms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .errors import LoperInputError
from .filtering import lowpass

__all__ = [
    "ClockMap",
    "sync_pulse_starts",
    "pulse_train_at",
    "sync_pulse_train",
    "rising_edges",
    "clock_map",
    "robot_log_on_mocap_frames",
    "perturbation_onsets",
    "MIN_MATCHED_EDGES",
    "OUTPUT_COLUMNS",
]

#: Fewest edges that must pair up between the two records for a clock map.
MIN_MATCHED_EDGES = 4

#: Columns of :func:`robot_log_on_mocap_frames`, in order.
OUTPUT_COLUMNS: tuple[str, ...] = ("time_s", "force_measured_n", "force_desired_n", "perturbation")

_LOG_COLUMNS = ("time_s", "force_desired_n", "force_measured_n", "sync_v", "perturbation")
_FORCE_COLUMNS = ("force_measured_n", "force_desired_n")
#: Pairing gate as a multiple of ``tolerance_s`` (edges farther from the line are unpaired).
_GATE_FACTOR = 10.0


def _src(source: str, default: str) -> str:
    return source if source else default


def _positive(value, name: str, source: str = "") -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v) or v <= 0:
        prefix = f"{source}: " if source else ""
        raise LoperInputError(f"{prefix}{name} must be a positive number, got {value!r}")
    return v


# ---------------------------------------------------------------------------
# the pulse train


@dataclass(frozen=True)
class ClockMap:
    """Linear map from the robot clock to the motion-capture clock.

    ``t_mocap = offset_s + scale * t_robot`` (both in s).

    Attributes
    ----------
    offset_s : float
        Mocap time of robot time 0, s (positive: the robot log started after
        the mocap recording).
    scale : float
        Mocap seconds per robot second (1 + drift; 1.00015 is +150 ppm).
    rms_residual_s : float
        RMS of the matched mocap edge times about the fitted line, s.
    n_edges : int
        Number of edge pairs the line was fitted through.
    """

    offset_s: float
    scale: float
    rms_residual_s: float
    n_edges: int

    @property
    def drift_ppm(self) -> float:
        """``(scale - 1) * 1e6``."""
        return (self.scale - 1.0) * 1e6

    def to_mocap(self, robot_time_s) -> np.ndarray:
        """Robot-clock times (s, any shape) on the mocap clock (s, same shape)."""
        return self.offset_s + self.scale * np.asarray(robot_time_s, dtype=float)

    def to_robot(self, mocap_time_s) -> np.ndarray:
        """Mocap-clock times (s, any shape) on the robot clock (s, same shape)."""
        return (np.asarray(mocap_time_s, dtype=float) - self.offset_s) / self.scale


def sync_pulse_starts(
    duration_s: float,
    seed: int | np.random.SeedSequence,
    min_interval_s: float = 0.5,
    max_interval_s: float = 1.5,
) -> np.ndarray:
    """Start times of the pseudo-random sync pulses, s on the robot clock.

    Intervals are drawn uniformly in [``min_interval_s``, ``max_interval_s``)
    from ``numpy.random.default_rng(seed)``; the first pulse starts one drawn
    interval after t = 0 (the record begins low). Pulses starting at or after
    ``duration_s`` are dropped. The draws of a longer train begin with those of
    a shorter one (same seed), so the train does not depend on where it is cut.

    With intervals spread over 1 s, two windows of 4 consecutive intervals agree
    within +-7.5 ms per interval with probability ~ (0.015)**4 ~ 5e-8: any 5
    consecutive edges identify their place in the train.

    Returns
    -------
    numpy.ndarray, shape (n_pulses,)
        Strictly increasing start times, s, in (0, duration_s).

    Raises
    ------
    LoperInputError
        Non-positive duration or interval, ``max_interval_s <= min_interval_s``
        (equal bounds would give a periodic, ambiguous train).
    """
    duration = _positive(duration_s, "duration_s")
    lo = _positive(min_interval_s, "min_interval_s")
    hi = _positive(max_interval_s, "max_interval_s")
    if not hi > lo:
        raise LoperInputError(
            f"max_interval_s ({max_interval_s}) must exceed min_interval_s ({min_interval_s}): "
            "equal intervals give a periodic train whose whole-period offset cannot be resolved"
        )
    rng = np.random.default_rng(seed)
    n = int(math.ceil(duration / lo)) + 1
    starts = np.cumsum(rng.uniform(lo, hi, n))
    return starts[starts < duration]


def pulse_train_at(time_s, starts_s, pulse_s: float = 0.01, level_v: float = 5.0) -> np.ndarray:
    """The sync output at arbitrary robot-clock times: ``level_v`` within a pulse, else 0 V.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Robot-clock times at which to sample, s.
    starts_s : array_like, shape (n_pulses,)
        Strictly increasing pulse start times, s (:func:`sync_pulse_starts`).
    pulse_s : float
        Pulse length, s; a time t is high if ``start <= t < start + pulse_s``.
    level_v : float
        High level, V.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Sync voltage, V.
    """
    t = np.asarray(time_s, dtype=float)
    starts = np.asarray(starts_s, dtype=float)
    width = _positive(pulse_s, "pulse_s")
    if starts.ndim != 1 or (starts.size > 1 and np.any(np.diff(starts) <= 0)):
        raise LoperInputError("starts_s must be a 1-D strictly increasing array of pulse start times")
    if starts.size == 0:
        return np.zeros(t.shape)
    k = np.searchsorted(starts, t, side="right") - 1
    high = (k >= 0) & (t - starts[np.clip(k, 0, None)] < width)
    return np.where(high, float(level_v), 0.0)


def sync_pulse_train(
    duration_s: float,
    sample_rate_hz: float,
    seed: int | np.random.SeedSequence,
    min_interval_s: float = 0.5,
    max_interval_s: float = 1.5,
    pulse_s: float = 0.01,
    level_v: float = 5.0,
) -> np.ndarray:
    """The robot's sync output for walking trials: pulses at pseudo-random intervals.

    Samples, at ``k / sample_rate_hz`` (k = 0 .. round(duration_s *
    sample_rate_hz) - 1), the train of :func:`sync_pulse_starts` with pulses of
    ``pulse_s`` at ``level_v`` (:func:`pulse_train_at`). The same train seen by
    another clock is ``pulse_train_at(clock_map.to_robot(t_mocap), starts)``.

    Parameters
    ----------
    duration_s : float
        Record length, s.
    sample_rate_hz : float
        Sampling rate, Hz (1000 for the robot log).
    seed : int or numpy.random.SeedSequence
        Seed of the interval draws.
    min_interval_s, max_interval_s : float
        Bounds of the uniform pulse-start intervals, s.
    pulse_s : float
        Pulse length, s; shorter than ``min_interval_s`` and at least 2 samples.
    level_v : float
        High level, V (> 0).

    Returns
    -------
    numpy.ndarray, shape (round(duration_s * sample_rate_hz),)
        Sync voltage, V.
    """
    rate = _positive(sample_rate_hz, "sample_rate_hz")
    width = _positive(pulse_s, "pulse_s")
    _positive(level_v, "level_v")
    if not width < float(min_interval_s):
        raise LoperInputError(f"pulse_s ({pulse_s}) must be shorter than min_interval_s ({min_interval_s})")
    if width * rate < 2:
        raise LoperInputError(f"pulse_s ({pulse_s}) must hold at least 2 samples at {rate} Hz")
    starts = sync_pulse_starts(duration_s, seed, min_interval_s, max_interval_s)
    n = int(round(float(duration_s) * rate))
    return pulse_train_at(np.arange(n) / rate, starts, width, level_v)


# ---------------------------------------------------------------------------
# edges


def rising_edges(signal_v, sample_rate_hz: float, threshold_v: float | None = None, source: str = "") -> np.ndarray:
    """Times of the rising edges of a pulse signal, with sub-sample interpolation.

    An edge is where the signal crosses ``threshold_v`` upward, placed by
    linear interpolation between the two samples either side. A hysteresis
    band (half the distance from the threshold to the nearer level, on either
    side) rejects noise: an upward crossing counts only if the signal was last
    at or below the band's lower bound and next reaches its upper bound; of
    several crossings within one rise the last counts.

    Parameters
    ----------
    signal_v : array_like, shape (n,)
        Sync signal, V, sampled uniformly. NaN samples are missing: an edge
        next to or inside a gap is not reported.
    sample_rate_hz : float
        Sampling rate, Hz.
    threshold_v : float, optional
        Threshold, V, strictly between the signal's low and high levels
        (its finite minimum and maximum); default halfway.
    source : str
        Names the signal (file, channel) in error messages.

    Returns
    -------
    numpy.ndarray, shape (n_edges,)
        Edge times, s, relative to sample 0 (``index / sample_rate_hz``).

    Raises
    ------
    LoperInputError
        Not 1-D, infinite values, no finite sample, a flat signal, a threshold
        outside the levels, fewer than 2 edges.
    """
    src = _src(source, "sync signal")
    rate = _positive(sample_rate_hz, "sample_rate_hz", src)
    x = np.asarray(signal_v, dtype=float)
    if x.ndim != 1:
        raise LoperInputError(f"{src}: the sync signal must be 1-D, got shape {x.shape}")
    if np.any(np.isinf(x)):
        i = int(np.flatnonzero(np.isinf(x))[0])
        raise LoperInputError(f"{src}: the sync signal is infinite at sample {i} ({x[i]})")
    finite = np.isfinite(x)
    if not finite.any():
        raise LoperInputError(f"{src}: the sync signal has no finite sample (all {x.size} are NaN or it is empty)")
    low, high = float(x[finite].min()), float(x[finite].max())
    if not high - low > 1e-9 * max(1.0, abs(high), abs(low)):
        raise LoperInputError(f"{src}: the sync signal is flat (every finite sample is {low:.6g} V): no pulses")
    thr = 0.5 * (low + high) if threshold_v is None else float(threshold_v)
    if not low < thr < high:
        raise LoperInputError(
            f"{src}: threshold_v = {threshold_v!r} V lies outside the signal's levels ({low:.6g} .. {high:.6g} V)"
        )
    band = 0.5 * min(thr - low, high - thr)
    n = x.size
    # state: 0 low (<= thr - band), 1 high (>= thr + band), -1 missing (breaks an edge), 2 undecided
    state = np.full(n, 2, dtype=np.int8)
    state[x <= thr - band] = 0
    state[x >= thr + band] = 1
    state[~finite] = -1
    idx = np.arange(n)
    decided = state != 2
    last = np.maximum.accumulate(np.where(decided, idx, -1))
    nxt = np.minimum.accumulate(np.where(decided, idx, n)[::-1])[::-1]
    before = np.where(last >= 0, state[np.clip(last, 0, None)], 2)
    after = np.where(nxt < n, state[np.clip(nxt, None, n - 1)], 2)
    c = np.flatnonzero((x[:-1] < thr) & (x[1:] >= thr)) + 1  # first sample at/above the threshold
    c = c[(before[c - 1] == 0) & (after[c] == 1)]
    if c.size:
        key = nxt[c]
        c = c[np.append(key[1:] != key[:-1], True)]  # last crossing of each rise
    if c.size < 2:
        raise LoperInputError(
            f"{src}: the sync signal has {c.size} rising edge(s) through {thr:.6g} V; at least 2 are needed"
        )
    x0, x1 = x[c - 1], x[c]
    return (c - 1 + (thr - x0) / (x1 - x0)) / rate


# ---------------------------------------------------------------------------
# clock map


def _check_edges(edges, name: str, src: str) -> np.ndarray:
    e = np.asarray(edges, dtype=float)
    if e.ndim != 1:
        raise LoperInputError(f"{src}: {name} must be 1-D, got shape {e.shape}")
    if not np.all(np.isfinite(e)):
        i = int(np.flatnonzero(~np.isfinite(e))[0])
        raise LoperInputError(f"{src}: {name} is not finite at edge {i} ({e[i]})")
    if e.size > 1 and np.any(np.diff(e) <= 0):
        i = int(np.flatnonzero(np.diff(e) <= 0)[0]) + 1
        raise LoperInputError(f"{src}: {name} must be strictly increasing; edge {i} ({e[i]:.9g} s) is not")
    if e.size < MIN_MATCHED_EDGES:
        raise LoperInputError(
            f"{src}: {name} has {e.size} edge(s); a clock map needs at least {MIN_MATCHED_EDGES} in each record"
        )
    return e


def _fit(r: np.ndarray, m: np.ndarray) -> tuple[float, float]:
    """Least-squares line m = a + b r (centred for conditioning)."""
    rc = r.mean()
    mc = m.mean()
    dr = r - rc
    sxx = float(dr @ dr)
    b = float(dr @ (m - mc)) / sxx if sxx > 0 else 1.0
    return mc - b * rc, b


def _pair(r: np.ndarray, m: np.ndarray, a: float, b: float, gate: float) -> tuple[np.ndarray, np.ndarray]:
    """Each robot edge with its nearest mocap edge under m = a + b r, within ``gate``, one-to-one."""
    mapped = a + b * r
    pos = np.searchsorted(m, mapped)
    left = np.clip(pos - 1, 0, m.size - 1)
    right = np.clip(pos, 0, m.size - 1)
    j = np.where(np.abs(m[left] - mapped) <= np.abs(m[right] - mapped), left, right)
    res = np.abs(m[j] - mapped)
    i = np.flatnonzero(res <= gate)
    j, res = j[i], res[i]
    # one-to-one: keep the closest robot edge for each mocap edge
    order = np.lexsort((res, j))
    i, j = i[order], j[order]
    first = np.append(True, j[1:] != j[:-1])
    return i[first], j[first]


def clock_map(
    robot_edges_s,
    mocap_edges_s,
    max_drift: float = 1e-3,
    source: str = "",
    tolerance_s: float = 3e-3,
) -> ClockMap:
    """The robot -> mocap clock map from the sync edges seen by both records.

    Matching: every window of ``MIN_MATCHED_EDGES - 1`` consecutive robot
    intervals is compared with every mocap window; a window pair whose
    intervals all agree within ``2 * tolerance_s + max_drift * interval`` votes
    for its index shift. The most-voted shift gives edge pairs and a first
    least-squares line ``t_mocap = offset_s + scale * t_robot``; then every
    robot edge is paired with the nearest mocap edge under the line (within
    ``10 * tolerance_s``, so edges missing from either record, or a train cut
    at either end, are simply unpaired) and the line refitted, twice.

    Parameters
    ----------
    robot_edges_s : array_like, shape (n_r,)
        Rising-edge times on the robot clock, s, strictly increasing.
    mocap_edges_s : array_like, shape (n_m,)
        Rising-edge times on the mocap clock, s, strictly increasing.
    max_drift : float
        Largest relative clock drift expected (1e-3 = 1000 ppm).
    source : str
        Names the records (files) in error messages.
    tolerance_s : float
        Largest accepted |residual| of a paired edge about the line, s (a few
        samples of the slower record: 3 ms ~ 3 samples at 1 kHz).

    Returns
    -------
    ClockMap
        Offset (s), scale, RMS residual (s) and number of paired edges.

    Raises
    ------
    LoperInputError
        Fewer than ``MIN_MATCHED_EDGES`` edges in a record or paired; no window
        matches; an ambiguous match (another shift, inconsistent with the
        chosen line, fits at least half as many windows: e.g. a periodic
        train); |scale - 1| beyond ``max_drift``; a residual above
        ``tolerance_s``.
    """
    src = _src(source, "sync edges")
    r = _check_edges(robot_edges_s, "robot_edges_s", src)
    m = _check_edges(mocap_edges_s, "mocap_edges_s", src)
    drift = float(max_drift)
    if not (math.isfinite(drift) and 0 <= drift < 0.1):
        raise LoperInputError(f"{src}: max_drift must lie in [0, 0.1), got {max_drift!r}")
    tol = _positive(tolerance_s, "tolerance_s", src)
    gate = _GATE_FACTOR * tol
    w = MIN_MATCHED_EDGES - 1  # intervals per window

    dr, dm = np.diff(r), np.diff(m)
    ok = np.abs(dr[:, None] - dm[None, :]) <= 2 * tol + drift * np.maximum(dr[:, None], dm[None, :])
    nr, nm = dr.size - w + 1, dm.size - w + 1
    win = ok[:nr, :nm].copy()
    for k in range(1, w):
        win &= ok[k:k + nr, k:k + nm]
    ai, aj = np.nonzero(win)
    if ai.size == 0:
        raise LoperInputError(
            f"{src}: no {MIN_MATCHED_EDGES} consecutive sync edges of the robot log ({r.size} edges) match the "
            f"interval pattern of the mocap record ({m.size} edges) within {2 * tol * 1e3:.3g} ms + "
            f"{drift * 1e6:.4g} ppm: different trains, or too little overlap"
        )
    shift = ai - aj
    votes = np.bincount(shift - shift.min())
    best = int(np.argmax(votes)) + int(shift.min())
    sel = shift == best
    ri = np.unique((ai[sel, None] + np.arange(w + 1)).ravel())
    a, b = _fit(r[ri], m[ri - best])
    for _ in range(2):
        i, j = _pair(r, m, a, b, gate)
        if i.size < 2:
            break
        a, b = _fit(r[i], m[j])
    i, j = _pair(r, m, a, b, gate)
    if i.size < MIN_MATCHED_EDGES:
        raise LoperInputError(
            f"{src}: only {i.size} sync edge(s) pair up between the robot log and the mocap record; "
            f"a clock map needs at least {MIN_MATCHED_EDGES}"
        )
    a, b = _fit(r[i], m[j])

    # ambiguity: windows voting for a mapping other than the chosen line
    consistent = np.abs(m[aj] - (a + b * r[ai])) <= gate
    n_ok = int(consistent.sum())
    if (~consistent).any():
        alt = shift[~consistent]
        alt_votes = np.bincount(alt - alt.min())
        k_alt = int(np.argmax(alt_votes))
        v_alt = int(alt_votes[k_alt])
        if 2 * v_alt >= n_ok:
            pick = np.flatnonzero(~consistent & (shift == k_alt + alt.min()))[0]
            delta = m[aj[pick]] - (a + b * r[ai[pick]])
            raise LoperInputError(
                f"{src}: ambiguous sync match: {n_ok} edge window(s) support the chosen clock map, {v_alt} support "
                f"another whose offset differs by {delta:+.4f} s (a periodic pulse train cannot resolve whole "
                "periods; use pseudo-random intervals, sync_pulse_train)"
            )

    res = m[j] - (a + b * r[i])
    rms = float(np.sqrt(np.mean(res**2)))
    worst = int(np.argmax(np.abs(res)))
    if abs(res[worst]) > tol:
        raise LoperInputError(
            f"{src}: sync edges do not lie on one line: residual {res[worst] * 1e3:+.3f} ms at robot time "
            f"{r[i[worst]]:.6g} s exceeds tolerance_s = {tol * 1e3:.3g} ms (RMS {rms * 1e3:.3f} ms over "
            f"{i.size} edges): clock jump or distorted sync signal"
        )
    span = float(r[i[-1]] - r[i[0]])
    if abs(b - 1.0) > drift + 2 * tol / span:
        raise LoperInputError(
            f"{src}: clock drift {(b - 1) * 1e6:+.1f} ppm exceeds max_drift = {drift * 1e6:.4g} ppm"
        )
    return ClockMap(offset_s=float(a), scale=float(b), rms_residual_s=rms, n_edges=int(i.size))


# ---------------------------------------------------------------------------
# resampling


def robot_log_on_mocap_frames(
    log: pd.DataFrame,
    log_rate_hz: float,
    mocap_sync_v,
    analog_rate_hz: float,
    frame_time_s,
    cutoff_hz: float = 40.0,
    order: int = 4,
    source: str = "",
    analog_start_s: float | None = None,
    max_drift: float = 1e-3,
    tolerance_s: float = 3e-3,
) -> pd.DataFrame:
    """The robot log's forces and perturbation flag on the motion-capture frames.

    1. Clock map (:func:`clock_map`) from the rising edges of the log's
       ``sync_v`` (robot clock: ``time_s`` at the interpolated sample index)
       and of ``mocap_sync_v`` (mocap clock: ``analog_start_s + index /
       analog_rate_hz``).
    2. ``force_measured_n`` and ``force_desired_n`` low-passed at the robot
       rate (:func:`~loper_analysis.filtering.lowpass`: zero-phase
       Butterworth, ``order``, ``cutoff_hz``) before resampling.
    3. Robot sample times mapped to the mocap clock; forces linearly
       interpolated at ``frame_time_s``; ``perturbation`` taken from the
       nearest robot sample (never interpolated), so a flag's onset lands
       within one mocap frame (plus half a robot sample) of its mapped time.

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
        Force low-pass (DESIGN.md: 40 Hz, 4th order).
    source : str
        Names the files in error messages.
    analog_start_s : float, optional
        Mocap time of analog sample 0, s; default ``frame_time_s[0]`` (C3D:
        analog and point data start together).
    max_drift, tolerance_s : float
        Passed to :func:`clock_map`.

    Returns
    -------
    pandas.DataFrame, shape (n_frames, 4)
        Columns :data:`OUTPUT_COLUMNS`: ``time_s`` (s, mocap clock, =
        ``frame_time_s``), ``force_measured_n``, ``force_desired_n`` (N),
        ``perturbation`` (0.0/1.0, NaN outside the log). ``attrs["clock_map"]``
        holds the :class:`ClockMap`.

    Raises
    ------
    LoperInputError
        Missing columns, a ``time_s`` step inconsistent with ``log_rate_hz``,
        non-finite forces or frame times, an all-NaN or flat sync signal in
        either record, a clock map refused by :func:`clock_map`, no frame
        inside the log's span.
    """
    src = _src(source, "robot log")
    if not isinstance(log, pd.DataFrame):
        raise LoperInputError(f"{src}: log must be a pandas DataFrame, got {type(log).__name__}")
    missing = [c for c in _LOG_COLUMNS if c not in log.columns]
    if missing:
        raise LoperInputError(f"{src}: robot log lacks column(s) {', '.join(missing)}")
    rate = _positive(log_rate_hz, "log_rate_hz", src)
    arate = _positive(analog_rate_hz, "analog_rate_hz", src)
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
    frames = np.asarray(frame_time_s, dtype=float)
    if frames.ndim != 1 or frames.size == 0 or not np.all(np.isfinite(frames)) or np.any(np.diff(frames) <= 0):
        raise LoperInputError(f"{src}: frame_time_s must be a non-empty, finite, strictly increasing 1-D array")
    start = frames[0] if analog_start_s is None else float(analog_start_s)

    robot_rel = rising_edges(log["sync_v"].to_numpy(dtype=float, na_value=np.nan), rate,
                             source=f"{src}: robot log column 'sync_v'")
    mocap_rel = rising_edges(mocap_sync_v, arate, source=f"{src}: mocap sync channel")
    robot_edges = np.interp(robot_rel * rate, np.arange(t_log.size), t_log)
    cm = clock_map(robot_edges, start + mocap_rel, max_drift=max_drift, source=src, tolerance_s=tolerance_s)

    t_mapped = cm.to_mocap(t_log)
    inside = (frames >= t_mapped[0]) & (frames <= t_mapped[-1])
    if not inside.any():
        raise LoperInputError(
            f"{src}: no mocap frame ({frames[0]:.6g} .. {frames[-1]:.6g} s) lies within the robot log's span on "
            f"the mocap clock ({t_mapped[0]:.6g} .. {t_mapped[-1]:.6g} s)"
        )
    out = {"time_s": frames}
    for col in _FORCE_COLUMNS:
        f = log[col].to_numpy(dtype=float, na_value=np.nan)
        try:
            f = lowpass(f, rate, cutoff_hz, order)
        except LoperInputError as exc:
            raise LoperInputError(f"{src}: column '{col}': {exc}") from None
        out[col] = np.interp(frames, t_mapped, f, left=np.nan, right=np.nan)
    flag = log["perturbation"].to_numpy(dtype=float, na_value=np.nan)
    if not np.all(np.isin(flag, (0.0, 1.0))):
        k = int(np.flatnonzero(~np.isin(flag, (0.0, 1.0)))[0])
        raise LoperInputError(f"{src}: column 'perturbation', sample {k}: value {flag[k]!r} is not 0 or 1")
    pos = np.clip(np.searchsorted(t_mapped, frames), 1, t_mapped.size - 1)
    nearest = np.where(frames - t_mapped[pos - 1] <= t_mapped[pos] - frames, pos - 1, pos)
    out["perturbation"] = np.where(inside, flag[nearest], np.nan)
    result = pd.DataFrame(out, columns=list(OUTPUT_COLUMNS))
    result.attrs["clock_map"] = cm
    return result


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
