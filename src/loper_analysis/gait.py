"""Gait events, strides, time normalisation and stride outliers (DESIGN.md section 4).

* :func:`gait_events` - heel strikes and toe-offs from one treadmill belt's
  vertical ground-reaction force, with hysteresis and minimum phase durations.
* :func:`strides` - the stride table of one side (heel strike -> heel strike,
  with its toe-off).
* :func:`cut` / :func:`normalise` - resampling onto normalised time (stride,
  stance or swing, 0-100 %); :func:`window` - windows on absolute time around
  onsets (perturbation windows).
* :func:`iqr_outliers` - the per-sample 1.5-IQR rule and the stride-removal
  decision; :func:`check_enough_strides` - the warning when too few remain.

Time is in s, force in N; signals are sampled along axis 0. Event and phase
names are the module constants :data:`SIDES`, :data:`EVENTS` and :data:`PHASES`.
"""

from __future__ import annotations

import logging
import math
import warnings
from typing import Sequence

import numpy as np
import pandas as pd

from .errors import LoperInputError

__all__ = [
    "SIDES",
    "EVENTS",
    "PHASES",
    "EVENT_COLUMNS",
    "STRIDE_COLUMNS",
    "MIN_VALID_STRIDES",
    "TooFewStridesWarning",
    "gait_events",
    "strides",
    "cut",
    "normalise",
    "window",
    "window_times_s",
    "iqr_outliers",
    "check_enough_strides",
]

logger = logging.getLogger(__name__)

#: Sides of the body (one treadmill belt each).
SIDES: tuple[str, ...] = ("left", "right")
#: Gait events, in the order they appear in :func:`gait_events` tables.
EVENTS: tuple[str, ...] = ("heel_strike", "toe_off")
#: Normalisation phases: the whole stride (HS -> next HS), stance (HS -> TO), swing (TO -> next HS).
PHASES: tuple[str, ...] = ("stride", "stance", "swing")
#: Columns of the event table.
EVENT_COLUMNS: tuple[str, ...] = ("side", "event", "time_s", "sample")
#: Columns of the stride table.
STRIDE_COLUMNS: tuple[str, ...] = (
    "stride", "side", "heel_strike_s", "toe_off_s", "end_s", "duration_s", "stance_s", "swing_s",
)
#: Fewest strides per subject and condition that an average is built from (warning below).
MIN_VALID_STRIDES: int = 5

#: Stride-table columns bounding each phase.
_PHASE_BOUNDS: dict[str, tuple[str, str]] = {
    "stride": ("heel_strike_s", "end_s"),
    "stance": ("heel_strike_s", "toe_off_s"),
    "swing": ("toe_off_s", "end_s"),
}
_HS, _TO = 1, 0  # state codes: 1 = loaded (stance), 0 = unloaded (swing)


class TooFewStridesWarning(UserWarning):
    """Fewer valid strides than required remain for an average."""


# --------------------------------------------------------------------------- helpers


def _where(source: str) -> str:
    return f"{source}: " if source else ""


def _time(time_s, source: str, name: str = "time_s") -> np.ndarray:
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise LoperInputError(f"{_where(source)}{name} must be 1-D with >= 2 samples, got shape {t.shape}")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise LoperInputError(f"{_where(source)}{name} is not finite at sample {bad[0]}: {t[bad[0]]}")
    step = np.flatnonzero(np.diff(t) <= 0)
    if step.size:
        i = step[0] + 1
        raise LoperInputError(
            f"{_where(source)}{name} must increase strictly; sample {i} ({float(t[i])!r} s) "
            f"follows {float(t[i - 1])!r} s"
        )
    return t


def _finite_number(name: str, value, source: str, minimum: float | None = None) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise LoperInputError(f"{_where(source)}{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or (minimum is not None and v < minimum):
        bound = f" >= {minimum}" if minimum is not None else ""
        raise LoperInputError(f"{_where(source)}{name} must be a finite number{bound}, got {v!r}")
    return v


def _side(side: str, source: str) -> str:
    if side not in SIDES:
        raise LoperInputError(f"{_where(source)}side must be one of {SIDES}, got {side!r}")
    return side


# --------------------------------------------------------------------------- events


def _hysteresis_events(force: np.ndarray, on: float, off: float) -> tuple[np.ndarray, np.ndarray]:
    """Samples and kinds (1 = heel strike, 0 = toe-off) of the state changes of the hysteresis."""
    n = force.size
    state = np.full(n, -1, dtype=np.int8)
    state[force <= off] = _TO
    state[force >= on] = _HS  # on > off: the two sets are disjoint
    last = np.where(state >= 0, np.arange(n), -1)
    np.maximum.accumulate(last, out=last)
    held = np.where(last >= 0, state[np.maximum(last, 0)], -1)  # state carried through the dead band
    change = np.flatnonzero((held[1:] != held[:-1]) & (held[:-1] >= 0)) + 1
    return change, held[change].astype(np.int8)


def _drop_short_periods(
    samples: np.ndarray, kinds: np.ndarray, time: np.ndarray, min_stance_s: float, min_swing_s: float
) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Remove, shortest first, each stance or swing period shorter than its minimum (both bounding events)."""
    dropped: list[dict] = []
    while samples.size >= 2:
        t = time[samples]
        duration = np.diff(t)
        minimum = np.where(kinds[:-1] == _HS, min_stance_s, min_swing_s)
        short = np.flatnonzero(duration < minimum)
        if not short.size:
            break
        i = short[np.argmin(duration[short])]
        dropped.append({
            "phase": "stance" if kinds[i] == _HS else "swing",
            "start_s": float(t[i]),
            "end_s": float(t[i + 1]),
            "duration_s": float(duration[i]),
            "start_sample": int(samples[i]),
            "end_sample": int(samples[i + 1]),
        })
        samples = np.delete(samples, [i, i + 1])
        kinds = np.delete(kinds, [i, i + 1])
    return samples, kinds, dropped


def gait_events(
    time_s,
    vertical_force_n,
    side: str,
    threshold_on_n: float = 50.0,
    threshold_off_n: float = 20.0,
    min_stance_s: float = 0.2,
    min_swing_s: float = 0.2,
    source: str = "",
) -> pd.DataFrame:
    """Heel strikes and toe-offs from one belt's vertical ground-reaction force.

    A two-threshold (hysteresis) detector. A sample with force
    ``>= threshold_on_n`` sets the state "loaded", a sample with force
    ``<= threshold_off_n`` sets "unloaded"; samples in between keep the state.

    * **Heel strike** = the first sample with force ``>= threshold_on_n``
      after the force was last ``<= threshold_off_n``.
    * **Toe-off** = the first sample with force ``<= threshold_off_n`` after
      the force was last ``>= threshold_on_n``.

    The event time is ``time_s`` at that sample (no interpolation between
    samples). A trial starting inside the dead band has an unknown state until
    the first threshold is reached; that first reach is not an event.

    Periods shorter than the minimum durations are noise blips: a stance
    (heel strike -> toe-off) shorter than ``min_stance_s`` or a swing (toe-off
    -> heel strike) shorter than ``min_swing_s`` is removed with both bounding
    events, shortest first, until none remains (the surrounding periods
    merge). The periods before the first and after the last event are
    incomplete and never judged. Removed periods are logged (INFO) and listed
    in ``attrs["dropped"]``.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    vertical_force_n : array_like, shape (n_samples,)
        Vertical ground-reaction force of the belt under ``side``, in N; must be finite.
    side : {"left", "right"}
    threshold_on_n, threshold_off_n : float
        Loading and unloading thresholds in N; ``threshold_on_n > threshold_off_n``.
    min_stance_s, min_swing_s : float
        Shortest accepted stance and swing period in s (>= 0).
    source : str
        Name of the trial or file, quoted in error and log messages.

    Returns
    -------
    pandas.DataFrame
        One row per event, in time order: ``side``, ``event``
        (``heel_strike`` | ``toe_off``), ``time_s`` (s), ``sample`` (int,
        index into ``time_s``). Heel strikes and toe-offs alternate.
        ``attrs``: ``source``, ``side``, the thresholds and minimum
        durations, and ``dropped`` - a list of dicts (``phase``, ``start_s``,
        ``end_s``, ``duration_s``, ``start_sample``, ``end_sample``).

    Raises
    ------
    LoperInputError
        Non-finite or non-increasing time, non-finite force (the first sample
        is named), mismatched lengths, ``threshold_on_n <= threshold_off_n``,
        negative minimum durations, an unknown side, or no event at all.
    """
    side = _side(side, source)
    t = _time(time_s, source)
    f = np.asarray(vertical_force_n, dtype=float)
    if f.ndim != 1 or f.size != t.size:
        raise LoperInputError(
            f"{_where(source)}vertical_force_n has shape {f.shape}; time_s has {t.size} samples"
        )
    bad = np.flatnonzero(~np.isfinite(f))
    if bad.size:
        raise LoperInputError(f"{_where(source)}vertical_force_n is not finite at sample {bad[0]}: {f[bad[0]]}")
    on = _finite_number("threshold_on_n", threshold_on_n, source)
    off = _finite_number("threshold_off_n", threshold_off_n, source)
    if on <= off:
        raise LoperInputError(
            f"{_where(source)}threshold_on_n ({on} N) must exceed threshold_off_n ({off} N) for hysteresis"
        )
    min_stance = _finite_number("min_stance_s", min_stance_s, source, minimum=0.0)
    min_swing = _finite_number("min_swing_s", min_swing_s, source, minimum=0.0)

    samples, kinds = _hysteresis_events(f, on, off)
    samples, kinds, dropped = _drop_short_periods(samples, kinds, t, min_stance, min_swing)
    for d in dropped:
        logger.info(
            "%s%s side: dropped a %.3f s %s period (%.3f-%.3f s), shorter than the minimum",
            _where(source), side, d["duration_s"], d["phase"], d["start_s"], d["end_s"],
        )
    if not samples.size:
        raise LoperInputError(
            f"{_where(source)}no gait event in vertical_force_n ({side} side): the force never crosses "
            f"{off} N and {on} N in turn (range {f.min():.1f} .. {f.max():.1f} N)"
        )
    events = pd.DataFrame({
        "side": side,
        "event": np.where(kinds == _HS, "heel_strike", "toe_off"),
        "time_s": t[samples],
        "sample": samples.astype(np.int64),
    })
    events.attrs.update({
        "source": source, "side": side, "threshold_on_n": on, "threshold_off_n": off,
        "min_stance_s": min_stance, "min_swing_s": min_swing, "dropped": dropped,
    })
    return events


def strides(events: pd.DataFrame, side: str) -> pd.DataFrame:
    """Stride table of one side from an event table.

    A stride runs from a heel strike to the next heel strike of the same side
    and must contain exactly one toe-off (strictly between the two); strides
    without one (or with several) are dropped, as are the incomplete strides
    before the first and after the last heel strike.

    Parameters
    ----------
    events : pandas.DataFrame
        Columns ``side``, ``event``, ``time_s`` as returned by :func:`gait_events`
        (tables of both sides may be concatenated).
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
        Missing columns, an unknown side or non-finite event times.
    """
    source = str(events.attrs.get("source", "")) if isinstance(events, pd.DataFrame) else ""
    if not isinstance(events, pd.DataFrame) or not {"side", "event", "time_s"} <= set(events.columns):
        raise LoperInputError(f"{_where(source)}events must be a table with columns side, event, time_s")
    side = _side(side, source)
    mine = events[events["side"] == side]
    t = mine["time_s"].to_numpy(dtype=float)
    if not np.isfinite(t).all():
        raise LoperInputError(f"{_where(source)}events: time_s is not finite for the {side} side")
    hs = np.sort(t[mine["event"].to_numpy() == "heel_strike"])
    to = np.sort(t[mine["event"].to_numpy() == "toe_off"])
    start, end = hs[:-1], hs[1:]
    first = np.searchsorted(to, start, side="right")  # first toe-off after the start
    count = np.searchsorted(to, end, side="left") - first  # toe-offs strictly inside
    keep = count == 1
    start, end = start[keep], end[keep]
    toe_off = to[first[keep]] if to.size else np.empty(0)
    return pd.DataFrame({
        "stride": np.arange(start.size, dtype=np.int64),
        "side": side,
        "heel_strike_s": start,
        "toe_off_s": toe_off,
        "end_s": end,
        "duration_s": end - start,
        "stance_s": toe_off - start,
        "swing_s": end - toe_off,
    }, columns=list(STRIDE_COLUMNS))


# --------------------------------------------------------------------------- resampling


def _values(values, n_samples: int, source: str) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.ndim not in (1, 2) or v.shape[0] != n_samples:
        raise LoperInputError(
            f"{_where(source)}values must have shape (n_samples,) or (n_samples, k) with n_samples = "
            f"{n_samples} (the length of time_s), got {v.shape}"
        )
    return v


def _interpolate(t: np.ndarray, v: np.ndarray, targets: np.ndarray, source: str) -> np.ndarray:
    """Linear interpolation of ``v`` at ``targets`` (n_windows, n_points); windows must lie in the data."""
    n_windows, n_points = targets.shape
    lo_t, hi_t = targets.min(axis=1), targets.max(axis=1)
    outside = np.flatnonzero((lo_t < t[0]) | (hi_t > t[-1]))
    if outside.size:
        w = outside[0]
        raise LoperInputError(
            f"{_where(source)}window {w} ({float(lo_t[w])!r} .. {float(hi_t[w])!r} s) lies outside the data "
            f"({float(t[0])!r} .. {float(t[-1])!r} s); {outside.size} window(s) outside"
        )
    flat = targets.ravel()
    hi = np.clip(np.searchsorted(t, flat, side="right"), 1, t.size - 1)
    lo = hi - 1
    frac = (flat - t[lo]) / (t[hi] - t[lo])
    # non-finite samples inside a window are refused (counted with a cumulative sum, per window)
    bad = ~np.isfinite(v) if v.ndim == 1 else ~np.isfinite(v).all(axis=1)
    if bad.any():
        cum = np.concatenate([[0], np.cumsum(bad)])
        first = lo.reshape(n_windows, n_points).min(axis=1)
        last = hi.reshape(n_windows, n_points).max(axis=1)
        hit = np.flatnonzero(cum[last + 1] - cum[first] > 0)
        if hit.size:
            w = hit[0]
            s = first[w] + np.flatnonzero(bad[first[w]:last[w] + 1])[0]
            raise LoperInputError(
                f"{_where(source)}values are not finite at sample {s} (t = {float(t[s])!r} s), inside window {w}"
            )
    if v.ndim == 2:
        frac = frac[:, None]
    out = v[lo] + frac * (v[hi] - v[lo])
    return out.reshape((n_windows, n_points) + v.shape[1:])


def cut(time_s, values, starts_s, ends_s, n_points: int = 101, source: str = "") -> np.ndarray:
    """Time-normalise windows of a signal by linear interpolation.

    Window ``i`` is resampled onto ``n_points`` equally spaced times from
    ``starts_s[i]`` to ``ends_s[i]``, both included (0 .. 100 % for the
    default 101 points, in steps of 1 %).

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    values : array_like, shape (n_samples,) or (n_samples, k)
        Signal(s) in any unit. NaN policy: samples used by a window (the
        bracketing samples of its points) must be finite; others are not examined.
    starts_s, ends_s : array_like, shape (n_windows,)
        Window bounds in s, ``start < end``, inside ``time_s[0] .. time_s[-1]``.
    n_points : int
        Points per window (>= 2).
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    numpy.ndarray, shape (n_windows, n_points) or (n_windows, n_points, k)

    Raises
    ------
    LoperInputError
        Bad shapes, a window with ``start >= end`` or outside the data range,
        non-finite values inside a window.
    """
    t = _time(time_s, source)
    v = _values(values, t.size, source)
    if int(n_points) != n_points or n_points < 2:
        raise LoperInputError(f"{_where(source)}n_points must be an integer >= 2, got {n_points!r}")
    a = np.atleast_1d(np.asarray(starts_s, dtype=float))
    b = np.atleast_1d(np.asarray(ends_s, dtype=float))
    if a.ndim != 1 or a.shape != b.shape:
        raise LoperInputError(
            f"{_where(source)}starts_s {a.shape} and ends_s {b.shape} must be 1-D of equal length"
        )
    wrong = np.flatnonzero(~(np.isfinite(a) & np.isfinite(b) & (a < b)))
    if wrong.size:
        w = wrong[0]
        raise LoperInputError(
            f"{_where(source)}window {w} needs finite start < end, got {float(a[w])!r} .. {float(b[w])!r} s"
        )
    if not a.size:
        return np.empty((0, int(n_points)) + v.shape[1:])
    u = np.linspace(0.0, 1.0, int(n_points))
    targets = a[:, None] + (b - a)[:, None] * u
    targets[:, -1] = b  # exact end point (no round-off past the data end)
    return _interpolate(t, v, targets, source)


def normalise(
    time_s, values, stride_table: pd.DataFrame, phase: str = "stride", n_points: int = 101, source: str = ""
) -> np.ndarray:
    """:func:`cut` over the strides of a stride table for one phase.

    ``phase`` picks the window: ``"stride"`` heel strike -> next heel strike,
    ``"stance"`` heel strike -> toe-off, ``"swing"`` toe-off -> next heel
    strike (columns of :func:`strides`). Returns (n_strides, n_points[, k]).
    """
    if phase not in _PHASE_BOUNDS:
        raise LoperInputError(f"{_where(source)}phase must be one of {PHASES}, got {phase!r}")
    start, end = _PHASE_BOUNDS[phase]
    missing = {start, end} - set(stride_table.columns)
    if missing:
        raise LoperInputError(f"{_where(source)}stride_table lacks column(s) {sorted(missing)}")
    return cut(time_s, values, stride_table[start].to_numpy(float), stride_table[end].to_numpy(float),
               n_points, source)


def window_times_s(before_s: float, after_s: float, rate_hz: float) -> np.ndarray:
    """Relative time grid of :func:`window`, in s: ``k / rate_hz`` for every integer ``k``
    with ``-before_s <= k / rate_hz <= after_s`` (1e-9 sample tolerance); always contains 0."""
    before = _finite_number("before_s", before_s, "", minimum=0.0)
    after = _finite_number("after_s", after_s, "", minimum=0.0)
    rate = _finite_number("rate_hz", rate_hz, "")
    if rate <= 0:
        raise LoperInputError(f"rate_hz must be positive, got {rate_hz!r}")
    k0 = math.ceil(-before * rate - 1e-9)
    k1 = math.floor(after * rate + 1e-9)
    return np.arange(k0, k1 + 1) / rate


def window(time_s, values, onsets_s, before_s: float, after_s: float, rate_hz: float, source: str = "") -> np.ndarray:
    """Windows on absolute time around onsets, resampled by linear interpolation.

    Window ``i`` holds ``values`` at ``onsets_s[i] + window_times_s(before_s,
    after_s, rate_hz)`` - a fixed grid of step ``1 / rate_hz`` s, from
    ``before_s`` before to ``after_s`` after the onset (rounded inwards to
    the grid; the onset itself is a grid point). E.g. 25 ms before and 250 ms
    after at 128 Hz gives k = -3 .. 32, 36 points.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    values : array_like, shape (n_samples,) or (n_samples, k)
        Signal(s); NaN policy as :func:`cut`.
    onsets_s : array_like, shape (n_windows,)
        Onset times in s; every window must lie inside the data.
    before_s, after_s : float
        Span before and after each onset in s (>= 0).
    rate_hz : float
        Grid rate in Hz.
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    numpy.ndarray, shape (n_windows, n_grid) or (n_windows, n_grid, k)

    Raises
    ------
    LoperInputError
        Bad shapes or numbers, a window outside the data, non-finite values inside a window.
    """
    t = _time(time_s, source)
    v = _values(values, t.size, source)
    try:
        rel = window_times_s(before_s, after_s, rate_hz)
    except LoperInputError as exc:
        raise LoperInputError(f"{_where(source)}{exc}") from None
    onsets = np.atleast_1d(np.asarray(onsets_s, dtype=float))
    if onsets.ndim != 1:
        raise LoperInputError(f"{_where(source)}onsets_s must be 1-D, got shape {onsets.shape}")
    bad = np.flatnonzero(~np.isfinite(onsets))
    if bad.size:
        raise LoperInputError(f"{_where(source)}onsets_s is not finite at index {bad[0]}")
    if not onsets.size:
        return np.empty((0, rel.size) + v.shape[1:])
    return _interpolate(t, v, onsets[:, None] + rel, source)


# --------------------------------------------------------------------------- outliers


def iqr_outliers(
    values,
    whisker: float = 1.5,
    max_fraction: float = 0.2,
    names: Sequence[str] | None = None,
    source: str = "",
) -> pd.DataFrame:
    """Stride outliers by the per-sample IQR rule (DESIGN.md section 4).

    For every normalised time sample (and signal), Q1 and Q3 are taken across
    strides with :func:`numpy.percentile` (default ``method="linear"``: the
    quantile interpolates linearly between order statistics, position
    ``p/100 * (n - 1)``). A value is outlying if it is below
    ``Q1 - whisker * IQR`` or above ``Q3 + whisker * IQR`` (values on a bound
    are not outlying). Per stride and signal the fraction of outlying samples
    is computed; a stride is removed if that fraction exceeds
    ``max_fraction`` for any signal. For perturbation analysis pass only the
    samples of the analysis window (25 ms before to 250 ms after onset).

    Parameters
    ----------
    values : array_like, shape (n_strides, n_samples) or (n_strides, n_samples, k)
        Normalised strides (any unit), finite; at least 4 strides.
    whisker : float
        IQR multiple (>= 0).
    max_fraction : float
        Largest accepted fraction of outlying samples, 0 .. 1.
    names : sequence of str, optional
        Signal names (length k; one name for 2-D input). Default ``"signal"``
        for 2-D input, ``"signal_0" ..`` for 3-D input.
    source : str
        Name of the trial or subject, quoted in error messages.

    Returns
    -------
    pandas.DataFrame
        One row per stride (input order): ``stride`` (row index into
        ``values``), ``fraction_outlying_<name>`` per signal (0 .. 1),
        ``removed`` (bool), ``reason`` (e.g. ``"knee: 27.7 % of samples
        outside 1.5·IQR"``, signals joined by ``"; "``; empty if kept).

    Raises
    ------
    LoperInputError
        Fewer than 4 strides, bad shapes or names, non-finite values, bad settings.
    """
    v = np.asarray(values, dtype=float)
    if v.ndim not in (2, 3):
        raise LoperInputError(
            f"{_where(source)}values must have shape (n_strides, n_samples[, k]), got {v.shape}"
        )
    if v.shape[0] < 4:
        raise LoperInputError(f"{_where(source)}the IQR rule needs >= 4 strides, got {v.shape[0]}")
    if v.shape[1] < 1 or (v.ndim == 3 and v.shape[2] < 1):
        raise LoperInputError(f"{_where(source)}values has no samples: shape {v.shape}")
    bad = np.argwhere(~np.isfinite(v))
    if bad.size:
        raise LoperInputError(
            f"{_where(source)}values are not finite at stride {bad[0][0]}, sample {bad[0][1]}"
        )
    w = _finite_number("whisker", whisker, source, minimum=0.0)
    mf = _finite_number("max_fraction", max_fraction, source, minimum=0.0)
    if mf > 1:
        raise LoperInputError(f"{_where(source)}max_fraction must lie in 0 .. 1, got {mf!r}")
    x = v if v.ndim == 3 else v[:, :, None]
    k = x.shape[2]
    if names is None:
        names = ["signal"] if v.ndim == 2 else [f"signal_{j}" for j in range(k)]
    names = [str(n) for n in names]
    if len(names) != k or len(set(names)) != k:
        raise LoperInputError(f"{_where(source)}names must be {k} distinct names, got {names!r}")

    q1, q3 = np.percentile(x, [25.0, 75.0], axis=0)  # (n_samples, k) each
    iqr = q3 - q1
    outlying = (x < q1 - w * iqr) | (x > q3 + w * iqr)
    fraction = outlying.mean(axis=1)  # (n_strides, k)
    over = fraction > mf
    table = pd.DataFrame({"stride": np.arange(x.shape[0], dtype=np.int64)})
    for j, name in enumerate(names):
        table[f"fraction_outlying_{name}"] = fraction[:, j]
    table["removed"] = over.any(axis=1)
    table["reason"] = [
        "; ".join(f"{names[j]}: {100 * fraction[i, j]:.1f} % of samples outside {w:g}·IQR"
                  for j in np.flatnonzero(over[i]))
        for i in range(x.shape[0])
    ]
    table.attrs.update({"source": source, "whisker": w, "max_fraction": mf})
    return table


def check_enough_strides(n_kept: int, source: str, minimum: int = MIN_VALID_STRIDES) -> bool:
    """True if ``n_kept >= minimum``; otherwise warn (:class:`TooFewStridesWarning`,
    naming ``source`` and both counts) and return False."""
    if int(n_kept) >= int(minimum):
        return True
    warnings.warn(
        f"{source}: only {int(n_kept)} valid stride(s), fewer than the {int(minimum)} required",
        TooFewStridesWarning,
        stacklevel=2,
    )
    return False
