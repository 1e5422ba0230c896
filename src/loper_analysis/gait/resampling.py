"""Resampling of signals onto normalised time (strides, stance, swing) and onto windows around onsets.

* :func:`cut` / :func:`normalise` - resampling onto normalised time (stride,
  stance or swing, 0-100 %);
* :func:`window_times_s` / :func:`window` - windows on absolute time around
  onsets (perturbation windows).

Time is in s; signals are sampled along axis 0 and resampled by linear
interpolation. NaN policy: the samples a window uses must be finite.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from loper_analysis.checks import number, signal, time_vector, where
from loper_analysis.constants import PHASES
from loper_analysis.errors import LoperInputError

__all__ = ["PHASE_BOUNDS", "cut", "normalise", "window_times_s", "window"]

#: Samples of a time-normalised stride, stance or swing (config ``strides.n_points``).
N_POINTS: int = 101

#: Stride-table columns bounding each phase.
PHASE_BOUNDS: dict[str, tuple[str, str]] = {
    "stride": ("heel_strike_s", "end_s"),
    "stance": ("heel_strike_s", "toe_off_s"),
    "swing": ("toe_off_s", "end_s"),
}


def _interpolate(t: np.ndarray, v: np.ndarray, targets: np.ndarray, source: str) -> np.ndarray:
    """Linear interpolation of ``v`` at ``targets`` (n_windows, n_points); windows must lie in the data."""
    n_windows, n_points = targets.shape
    lo_t, hi_t = targets.min(axis=1), targets.max(axis=1)
    outside = np.flatnonzero((lo_t < t[0]) | (hi_t > t[-1]))
    if outside.size:
        w = outside[0]
        raise LoperInputError(
            f"{where(source)}window {w} ({float(lo_t[w])!r} .. {float(hi_t[w])!r} s) lies outside the data "
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
            s = first[w] + np.flatnonzero(bad[first[w] : last[w] + 1])[0]
            raise LoperInputError(
                f"{where(source)}values are not finite at sample {s} (t = {float(t[s])!r} s), inside window {w}"
            )
    if v.ndim == 2:
        frac = frac[:, None]
    out = v[lo] + frac * (v[hi] - v[lo])
    return out.reshape((n_windows, n_points) + v.shape[1:])


def cut(time_s, values, starts_s, ends_s, n_points: int = N_POINTS, source: str = "") -> np.ndarray:
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
    t = time_vector(time_s, source)
    v = signal("values", values, t.size, source)
    if int(n_points) != n_points or n_points < 2:
        raise LoperInputError(f"{where(source)}n_points must be an integer >= 2, got {n_points!r}")
    a = np.atleast_1d(np.asarray(starts_s, dtype=float))
    b = np.atleast_1d(np.asarray(ends_s, dtype=float))
    if a.ndim != 1 or a.shape != b.shape:
        raise LoperInputError(f"{where(source)}starts_s {a.shape} and ends_s {b.shape} must be 1-D of equal length")
    wrong = np.flatnonzero(~(np.isfinite(a) & np.isfinite(b) & (a < b)))
    if wrong.size:
        w = wrong[0]
        raise LoperInputError(
            f"{where(source)}window {w} needs finite start < end, got {float(a[w])!r} .. {float(b[w])!r} s"
        )
    if not a.size:
        return np.empty((0, int(n_points)) + v.shape[1:])
    u = np.linspace(0.0, 1.0, int(n_points))
    targets = a[:, None] + (b - a)[:, None] * u
    targets[:, -1] = b  # exact end point (no round-off past the data end)
    return _interpolate(t, v, targets, source)


def normalise(
    time_s, values, stride_table: pd.DataFrame, phase: str = "stride", n_points: int = N_POINTS, source: str = ""
) -> np.ndarray:
    """:func:`cut` over the strides of a stride table for one phase.

    ``phase`` picks the window: ``"stride"`` heel strike -> next heel strike,
    ``"stance"`` heel strike -> toe-off, ``"swing"`` toe-off -> next heel
    strike (columns of :func:`loper_analysis.gait.strides.strides_from_events`). Returns (n_strides, n_points[, k]).
    """
    if phase not in PHASE_BOUNDS:
        raise LoperInputError(f"{where(source)}phase must be one of {PHASES}, got {phase!r}")
    start, end = PHASE_BOUNDS[phase]
    missing = {start, end} - set(stride_table.columns)
    if missing:
        raise LoperInputError(f"{where(source)}stride_table lacks column(s) {sorted(missing)}")
    return cut(time_s, values, stride_table[start].to_numpy(float), stride_table[end].to_numpy(float), n_points, source)


def window_times_s(before_s: float, after_s: float, rate_hz: float) -> np.ndarray:
    """Relative time grid of :func:`window`, in s: ``k / rate_hz`` for every integer ``k``
    with ``-before_s <= k / rate_hz <= after_s`` (1e-9 sample tolerance); always contains 0."""
    before = number("before_s", before_s, "", minimum=0.0)
    after = number("after_s", after_s, "", minimum=0.0)
    rate = number("rate_hz", rate_hz, "")
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
        Name of the trial, quoted in error messages (bad shapes or numbers,
        a window outside the data, non-finite values inside a window).

    Returns an array of shape (n_windows, n_grid) or (n_windows, n_grid, k).
    """
    t = time_vector(time_s, source)
    v = signal("values", values, t.size, source)
    try:
        rel = window_times_s(before_s, after_s, rate_hz)
    except LoperInputError as exc:
        raise LoperInputError(f"{where(source)}{exc}") from None
    onsets = np.atleast_1d(np.asarray(onsets_s, dtype=float))
    if onsets.ndim != 1:
        raise LoperInputError(f"{where(source)}onsets_s must be 1-D, got shape {onsets.shape}")
    bad = np.flatnonzero(~np.isfinite(onsets))
    if bad.size:
        raise LoperInputError(f"{where(source)}onsets_s is not finite at index {bad[0]}")
    if not onsets.size:
        return np.empty((0, rel.size) + v.shape[1:])
    return _interpolate(t, v, onsets[:, None] + rel, source)
