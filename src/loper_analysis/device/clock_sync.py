"""The robot clock on the motion-capture clock: rising edges of the sync pulses and the clock map.

The robot (LOPER) logs at 1000 Hz on its own clock
(:mod:`loper_analysis.io.robot_log`); the motion-capture system records
markers at 128 Hz and analogs at 1024 Hz, one analog channel of which is the
robot's sync output (V). The two clocks differ by an offset (recording starts
seconds apart, either sign) and a small drift (up to a few hundred ppm)::

    t_mocap = offset_s + scale * t_robot

Both are found from the rising edges of the sync signal as seen by both
records (:func:`rising_edges`, :func:`clock_map`); the robot's sync output
is a pulse train with pseudo-random intervals
(:func:`loper_analysis.synthetic.sync.sync_pulse_starts` in synthetic trials).

Polarity: the intervals between the rising edges cannot tell a pulse's start
from its end (an active-low output inverted in one record only has its
"rising edges" at the pulses' ends, with the same intervals), so a clock map
built from such records is off by the pulse width. :func:`clock_map` therefore
also compares each paired pulse's high time (rising to next falling edge,
:func:`high_times`) in both records when given them, and refuses records that
disagree.

Noise: before the edges are matched, :func:`require_pulse_train` checks that a sync signal looks like a pulse
train at all (two levels, each much narrower than the swing between them); a channel holding noise (an
unplugged cable, the wrong channel) would otherwise give random edges and a refusal blaming "different trains".

Edge-time convention: an edge is placed where the straight line between the
last sample below and the first sample at or above the threshold crosses it,
so a sharp step sampled at rate f_s is located to within +-0.5 / f_s, without
bias when the step falls at a random instant between samples (how the mocap
analog input sees it). A robot whose sync output is a zero-order hold
updated at its own samples would shift every robot edge by a constant half
robot sample (0.5 ms at 1000 Hz), i.e. the offset by 0.5 ms: far below one
mocap frame (7.8 ms).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError

__all__ = [
    "MIN_MATCHED_EDGES",
    "HIGH_TIME_TOLERANCE",
    "MIN_LEVEL_SEPARATION",
    "ClockMap",
    "rising_edges",
    "high_times",
    "require_pulse_train",
    "clock_map",
]

#: Fewest edges that must pair up between the two records for a clock map.
MIN_MATCHED_EDGES = 4
#: Pairing gate as a multiple of ``tolerance_s`` (edges farther from the line are unpaired).
_GATE_FACTOR = 10.0
#: Largest accepted difference of a pulse's high time between the two records, as a share of the pulse's period
#: (added to ``2 * tolerance_s``): 5 % tells a duty ratio d from 1 - d unless d lies within about 0.47 .. 0.53.
HIGH_TIME_TOLERANCE = 0.05
#: Smallest separation of a pulse train's two levels, in units of their spread (:func:`require_pulse_train`): each
#: level's robust SD at most 1/8 of the swing keeps the hysteresis band of :func:`rising_edges` (a quarter of the
#: swing from either level) at least 2 SDs from it. Noise gives 2 to 3 (Gaussian 2.3, uniform 2.7), a mains sine
#: 3.9, a 5 V train with 0.1 V of noise about 50.
MIN_LEVEL_SEPARATION = 8.0


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
    src = source or "sync signal"
    rate = positive("sample_rate_hz", sample_rate_hz, src)
    x, thr, band = _levels(signal_v, threshold_v, src)
    c = _upward_crossings(x, thr, band)
    if c.size < 2:
        raise LoperInputError(
            f"{src}: the sync signal has {c.size} rising edge(s) through {thr:.6g} V; at least 2 are needed"
        )
    return c / rate


def high_times(
    signal_v, sample_rate_hz: float, rising_s, threshold_v: float | None = None, source: str = ""
) -> np.ndarray:
    """How long each pulse stays high: from each rising edge to the next falling edge, s.

    Falling edges are found like :func:`rising_edges` finds rising ones (same
    threshold, hysteresis band and interpolation, mirrored), so the high time
    of a sharp pulse is exact to within a sample; the ratio of high time to
    the interval between rising edges is the duty ratio. A pulse train and its
    inverse have the same rising-edge intervals but high times of ``w`` and
    ``period - w``.

    Parameters
    ----------
    signal_v : array_like, shape (n,)
        Sync signal, V (as for :func:`rising_edges`; NaN = missing).
    sample_rate_hz : float
        Sampling rate, Hz.
    rising_s : array_like, shape (n_edges,)
        Its rising edges, s relative to sample 0, from :func:`rising_edges`
        with the same ``threshold_v``.
    threshold_v : float, optional
        Threshold, V; default halfway between the signal's levels.
    source : str
        Names the signal (file, channel) in error messages.

    Returns
    -------
    numpy.ndarray, shape (n_edges,)
        High time of each pulse, s; NaN where no falling edge is seen before
        the next rising edge (the record ends high, or the edge lies in a gap).

    Raises
    ------
    LoperInputError
        As :func:`rising_edges` for the signal itself.
    """
    src = source or "sync signal"
    rate = positive("sample_rate_hz", sample_rate_hz, src)
    x, thr, band = _levels(signal_v, threshold_v, src)
    rising = np.asarray(rising_s, dtype=float).ravel()
    falling = _upward_crossings(-x, -thr, band) / rate
    out = np.full(rising.size, np.nan)
    if not falling.size or not rising.size:
        return out
    k = np.searchsorted(falling, rising, side="right")
    has = k < falling.size
    f = np.where(has, falling[np.clip(k, None, falling.size - 1)], np.inf)
    nxt = np.append(rising[1:], np.inf)
    ok = has & (f < nxt)
    out[ok] = f[ok] - rising[ok]
    return out


def require_pulse_train(signal_v, sample_rate_hz: float, source: str = "") -> dict:
    """Refuse a sync signal that is no pulse train (noise, an unplugged cable) before its edges are matched.

    The finite samples are split in two where the split separates them best (Otsu: largest between-class
    variance); each class's level is its median, its spread its robust SD (1.4826 x MAD). A pulse train sits at
    one of two levels but for its edges: they lie at least :data:`MIN_LEVEL_SEPARATION` (8) larger spreads
    apart. Noise gives 2 to 3 and is refused, naming the levels, the share of samples in the middle half between
    them and the crossings of the halfway level. Signals with fewer than two distinct finite values (empty, all
    NaN, flat) are left to :func:`rising_edges`, which names them.

    Parameters
    ----------
    signal_v : array_like, shape (n,)
        Sync signal, V (NaN = missing).
    sample_rate_hz : float
        Sampling rate, Hz (for the duration named in the message).
    source : str
        Names the signal (file, channel) in error messages.

    Returns
    -------
    dict
        ``low_v``, ``high_v`` (levels, V), ``separation`` (their distance over the larger spread; inf without
        noise), ``middle_fraction``, ``crossings``; empty when the signal was left to :func:`rising_edges`.

    Raises
    ------
    LoperInputError
        A separation below :data:`MIN_LEVEL_SEPARATION`: "no pulse train", naming the source, what the signal
        holds and the likely cause.
    """
    src = source or "sync signal"
    rate = positive("sample_rate_hz", sample_rate_hz, src)
    x = np.asarray(signal_v, dtype=float)
    if x.ndim != 1:
        return {}
    finite = x[np.isfinite(x)]
    v = np.sort(finite)
    if v.size < 2 or v[0] == v[-1]:
        return {}
    n = v.size
    k = np.arange(1, n)
    c = np.cumsum(v - v[0])  # shifted for conditioning
    m0 = c[:-1] / k
    m1 = (c[-1] - c[:-1]) / (n - k)
    between = (k / n) * (1 - k / n) * (m1 - m0) ** 2
    between[v[1:] == v[:-1]] = -1.0  # split only between distinct values
    i = int(np.argmax(between)) + 1
    low, high = v[:i], v[i:]
    lo_v, hi_v = float(np.median(low)), float(np.median(high))
    spread = 1.4826 * max(float(np.median(np.abs(low - lo_v))), float(np.median(np.abs(high - hi_v))))
    swing = hi_v - lo_v
    sep = swing / spread if spread > 0 else math.inf
    mid = float(np.mean((finite > lo_v + swing / 4) & (finite < hi_v - swing / 4)))
    half = 0.5 * (lo_v + hi_v)
    above = finite >= half
    crossings = int(np.count_nonzero(above[1:] != above[:-1]))
    out = {"low_v": lo_v, "high_v": hi_v, "separation": sep, "middle_fraction": mid, "crossings": crossings}
    if sep >= MIN_LEVEL_SEPARATION:
        return out
    raise LoperInputError(
        f"{src}: no pulse train: {crossings} crossings of the halfway level {half:.4g} V in "
        f"{x.size / rate:.4g} s, levels not two-valued (the samples spread about {lo_v:.4g} and {hi_v:.4g} V "
        f"by {spread:.3g} V, so the two levels lie only {sep:.2f} times their spread apart, a pulse train at "
        f"least {MIN_LEVEL_SEPARATION:g}; {mid:.0%} of the samples lie in the middle half between them, where a "
        "pulse train only passes at its edges): the channel holds noise. An unplugged sync cable, or the wrong "
        "channel?"
    )


def _levels(signal_v, threshold_v: float | None, src: str) -> tuple[np.ndarray, float, float]:
    """The signal as a float array, its threshold and hysteresis half-band (V); refuses unusable signals."""
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
    return x, thr, 0.5 * min(thr - low, high - thr)


def _upward_crossings(x: np.ndarray, thr: float, band: float) -> np.ndarray:
    """Upward crossings of ``thr`` with hysteresis ``band`` (see :func:`rising_edges`), in fractional samples."""
    n = x.size
    # state: 0 low (<= thr - band), 1 high (>= thr + band), -1 missing (breaks an edge), 2 undecided
    state = np.full(n, 2, dtype=np.int8)
    state[x <= thr - band] = 0
    state[x >= thr + band] = 1
    state[~np.isfinite(x)] = -1
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
    x0, x1 = x[c - 1], x[c]
    return c - 1 + (thr - x0) / (x1 - x0)


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


def _matching_windows(
    r: np.ndarray, m: np.ndarray, tol: float, drift: float, src: str
) -> tuple[np.ndarray, np.ndarray]:
    """First robot and mocap edge (indices, each shape (n_matches,)) of every pair of windows of
    ``MIN_MATCHED_EDGES - 1`` consecutive intervals that agree within ``2 * tol + drift * interval`` (s); edges
    ``r``, ``m`` in s. None matching raises LoperInputError."""
    w = MIN_MATCHED_EDGES - 1  # intervals per window
    dr, dm = np.diff(r), np.diff(m)
    ok = np.abs(dr[:, None] - dm[None, :]) <= 2 * tol + drift * np.maximum(dr[:, None], dm[None, :])
    nr, nm = dr.size - w + 1, dm.size - w + 1
    win = ok[:nr, :nm].copy()
    for k in range(1, w):
        win &= ok[k : k + nr, k : k + nm]
    ai, aj = np.nonzero(win)
    if ai.size == 0:
        raise LoperInputError(
            f"{src}: no {MIN_MATCHED_EDGES} consecutive sync edges of the robot log ({r.size} edges) match the "
            f"interval pattern of the mocap record ({m.size} edges) within {2 * tol * 1e3:.3g} ms + "
            f"{drift * 1e6:.4g} ppm: different trains, or too little overlap"
        )
    return ai, aj


def _check_unambiguous(
    r: np.ndarray,
    m: np.ndarray,
    windows: tuple[np.ndarray, np.ndarray],
    line: tuple[float, float],
    gate: float,
    src: str,
) -> None:
    """Refuse a match that another mapping fits nearly as well: the matching ``windows`` (first robot and mocap
    edge of each) off the chosen ``line`` (offset in s, scale) by more than ``gate`` (s) voting for one other
    shift at least half as often as those on it."""
    (ai, aj), (a, b) = windows, line
    shift = ai - aj
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
                "periods; use pseudo-random intervals, loper_analysis.synthetic.sync.sync_pulse_starts)"
            )


def clock_map(
    robot_edges_s,
    mocap_edges_s,
    *,
    max_drift: float = 1e-3,
    source: str = "",
    tolerance_s: float = 3e-3,
    robot_high_s=None,
    mocap_high_s=None,
    robot_name: str = "the robot log",
    mocap_name: str = "the mocap record",
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

    Polarity (when ``robot_high_s`` and ``mocap_high_s`` are given): the
    intervals cannot tell a pulse's start from its end, so the pulses' high
    times (:func:`high_times`) must agree too. Over the paired edges whose
    high time both records show, the median of ``|scale * robot_high -
    mocap_high| - HIGH_TIME_TOLERANCE * period`` (:data:`HIGH_TIME_TOLERANCE`,
    the period to the next mocap edge) must not exceed ``2 * tolerance_s``. A record whose
    sync is inverted (e.g. an active-low output: high for ``period - w``
    instead of ``w``) fails this, where the edge intervals alone would give a
    clock map off by the pulse width ``w``.

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
    robot_high_s, mocap_high_s : array_like, optional
        High time of the pulse starting at each edge, s (same shapes as the
        edges, NaN where unknown; :func:`high_times`). Both or neither; without
        them the polarity is not checked.
    robot_name, mocap_name : str
        Name the two sync signals (record and channel) in the polarity message.

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
        ``tolerance_s``; pulses whose high times disagree between the records
        (opposite polarity: naming both high times, ms, and the record whose
        sync looks inverted).
    """
    src = source or "sync edges"
    r = _check_edges(robot_edges_s, "robot_edges_s", src)
    m = _check_edges(mocap_edges_s, "mocap_edges_s", src)
    drift = float(max_drift)
    if not (math.isfinite(drift) and 0 <= drift < 0.1):
        raise LoperInputError(f"{src}: max_drift must lie in [0, 0.1), got {max_drift!r}")
    tol = positive("tolerance_s", tolerance_s, src)
    gate = _GATE_FACTOR * tol
    if (robot_high_s is None) != (mocap_high_s is None):
        raise LoperInputError(f"{src}: robot_high_s and mocap_high_s must be given together")
    if robot_high_s is not None:
        hr = np.asarray(robot_high_s, dtype=float)
        hm = np.asarray(mocap_high_s, dtype=float)
        if hr.shape != r.shape or hm.shape != m.shape:
            raise LoperInputError(
                f"{src}: high times of shapes {hr.shape} and {hm.shape} do not match the edges' {r.shape} and {m.shape}"
            )
    w = MIN_MATCHED_EDGES - 1  # intervals per window
    ai, aj = _matching_windows(r, m, tol, drift, src)
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

    _check_unambiguous(r, m, (ai, aj), (a, b), gate, src)

    if robot_high_s is not None:
        _check_polarity(m, i, j, b, hr, hm, tol, src, robot_name, mocap_name)

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
        raise LoperInputError(f"{src}: clock drift {(b - 1) * 1e6:+.1f} ppm exceeds max_drift = {drift * 1e6:.4g} ppm")
    return ClockMap(offset_s=float(a), scale=float(b), rms_residual_s=rms, n_edges=int(i.size))


def _check_polarity(
    m: np.ndarray,
    i: np.ndarray,
    j: np.ndarray,
    scale: float,
    robot_high: np.ndarray,
    mocap_high: np.ndarray,
    tol: float,
    src: str,
    robot_name: str,
    mocap_name: str,
) -> None:
    """Refuse paired pulses whose high times (s) disagree between the records (see :func:`clock_map`).

    Each paired pulse's period is the interval from its mocap edge to the next mocap edge (the paired
    trains have the same intervals); pulses without a next edge or a high time in either record are
    left out.
    """
    hr = scale * robot_high[i]
    hm = mocap_high[j]
    period = np.append(np.diff(m), np.nan)[j]
    use = np.isfinite(hr) & np.isfinite(hm) & np.isfinite(period)
    if use.sum() < 2:
        return  # too few complete pulses to judge (every edge at a gap or a record's end)
    hr, hm, period = hr[use], hm[use], period[use]
    if float(np.median(np.abs(hr - hm) - HIGH_TIME_TOLERANCE * period)) <= 2 * tol:
        return
    h_r, h_m = float(np.median(hr)), float(np.median(hm))
    d_r, d_m = float(np.median(hr / period)), float(np.median(hm / period))
    seen = (
        f"sync pulses high for {h_r * 1e3:.1f} ms (duty ratio {d_r:.3f}) in {robot_name} but for "
        f"{h_m * 1e3:.1f} ms (duty ratio {d_m:.3f}) in {mocap_name} (medians over {hr.size} paired pulses; "
        f"accepted difference 2 x {tol * 1e3:.3g} ms + {HIGH_TIME_TOLERANCE:.0%} of the period)"
    )
    if (d_r - 0.5) * (d_m - 0.5) < 0:
        which = (
            "the robot's sync looks inverted (active-low)"
            if d_r > d_m
            else "the mocap channel sees the sync inverted (active-low)"
        )
        raise LoperInputError(
            f"{src}: {seen}: {which}: its rising edges are the pulses' ends, which would put the clock map off by "
            f"the pulse width (~{min(h_r, h_m) * 1e3:.1f} ms); invert that record's sync signal before the clock map"
        )
    raise LoperInputError(
        f"{src}: {seen}: the two records do not see the same sync pulses (another signal, or a distorted one)"
    )
