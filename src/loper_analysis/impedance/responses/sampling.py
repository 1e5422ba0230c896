"""Cubic-spline sampling of signals inside their runs of finite frames, and the window spans of a response.

Samples at times between frames come from a cubic spline
(:class:`scipy.interpolate.CubicSpline`, not-a-knot) through the frames of
the run of finite samples that holds the window; at frame times it returns
the frame values. NaN policy: a window must lie inside one run of finite
samples (NaN elsewhere, e.g. forces outside the robot log, is allowed).
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from loper_analysis.checks import number, where
from loper_analysis.errors import LoperInputError

__all__ = ["TIME_TOLERANCE_S", "SplineSampler", "window_span"]

#: Tolerance of time comparisons on exact quantities (grids, swing lengths), s.
TIME_TOLERANCE_S = 1e-9


def window_span(start_s, end_s, source: str = "") -> tuple[float, float]:
    """A window relative to the onset, ``start_s <= 0 <= end_s`` (s)."""
    a = number("start_s", start_s, source)
    b = number("end_s", end_s, source)
    if not a <= 0.0 <= b:
        raise LoperInputError(f"{where(source)}the window must hold the onset: start_s <= 0 <= end_s, got {a} .. {b} s")
    return a, b


class SplineSampler:
    """Cubic-spline sampling of ``values`` (n, k) inside its runs of finite frames."""

    def __init__(self, t: np.ndarray, values: np.ndarray):
        self.t = t
        self.v = values.reshape(len(t), -1)
        finite = np.isfinite(self.v).all(axis=1)
        edge = np.diff(np.concatenate([[0], finite.astype(np.int8), [0]]))
        starts, stops = np.flatnonzero(edge == 1), np.flatnonzero(edge == -1)
        long = stops - starts >= 2
        self.starts, self.stops = starts[long], stops[long]
        self.t0, self.t1 = t[self.starts], t[self.stops - 1]
        self.tol = 1e-3 * float(np.median(np.diff(t)))  # TSV times are rounded to ~1e-6 s
        self._splines: dict[int, CubicSpline] = {}

    def run(self, lo, hi) -> np.ndarray:
        """Index of the finite run holding each span ``lo .. hi`` (broadcast), -1 if none."""
        lo, hi = np.broadcast_arrays(np.asarray(lo, float), np.asarray(hi, float))
        if not self.t0.size:
            return np.full(lo.shape, -1)
        i = np.searchsorted(self.t0, lo + self.tol, side="right") - 1
        ic = np.clip(i, 0, None)
        ok = (i >= 0) & (lo >= self.t0[ic] - self.tol) & (hi <= self.t1[ic] + self.tol)
        return np.where(ok, i, -1)

    def finite_spans(self) -> str:
        return ", ".join(f"{a:.4f} .. {b:.4f} s" for a, b in zip(self.t0, self.t1)) or "none"

    def __call__(self, targets: np.ndarray, runs: np.ndarray) -> np.ndarray:
        """Values at ``targets`` (w, p) whose rows lie in ``runs`` (w,) (all >= 0): (w, p, k)."""
        out = np.empty(targets.shape + (self.v.shape[1],))
        for r in np.unique(runs):
            if r not in self._splines:
                a, b = self.starts[r], self.stops[r]
                self._splines[r] = CubicSpline(self.t[a:b], self.v[a:b], axis=0)
            sel = runs == r
            out[sel] = self._splines[r](targets[sel])
        return out
