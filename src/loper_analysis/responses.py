"""Perturbation responses: matched unperturbed strides, paired windows, outliers, subject averages.

DESIGN.md section 4 "Perturbed strides": for each perturbed stride the
unperturbed stride of the same trial that is most similar just before the
onset is its reference; the response is perturbed minus matched
unperturbed; pairs are judged by the IQR outlier rule on the analysis window
only and averaged per subject and onset. The averaged pair is also what the
identification (:func:`loper_analysis.identification.prepare_window`) fits.

* :func:`too_short` - perturbed strides whose swing cannot hold the window.
* :func:`match_unperturbed` - the matched unperturbed stride and its anchor.
* :func:`paired_windows` - perturbed and matched unperturbed windows on one
  relative time grid (onset at t = 0).
* :func:`window_outliers` - the IQR rule on the analysis window of the differences.
* :func:`subject_onset_response` - all of it for one subject and onset, over
  the subject's trials: the mean response table, the stride counts and the
  averaged series for the identification.
* :func:`null_pair_windows` - unperturbed strides paired the same way: the
  stride-to-stride noise the identification weights its errors by.

Conventions
-----------
* Times in s on the motion-capture clock; angles in rad (flexion and
  dorsiflexion positive); forces in N; ``pelvis_x`` in m.
* Alignment: a candidate unperturbed stride ``u`` is aligned to a perturbed
  stride ``p`` at the same time after its own toe-off,
  ``anchor_u = toe_off_u + (onset_p - toe_off_p)``; relative time 0 is the
  onset in ``p`` and the anchor in ``u``.
* Interpolation: samples at times between frames come from a cubic spline
  (:class:`scipy.interpolate.CubicSpline`, not-a-knot) through the frames of
  the run of finite samples that holds the window; at frame times it returns
  the frame values. NaN policy: a window must lie inside one run of finite
  samples (NaN elsewhere, e.g. forces outside the robot log, is allowed).
"""

from __future__ import annotations

import logging
import math
import os
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline

from .constants import JOINTS
from .dynamics import segment_coordinates
from .errors import LoperInputError
from .gait import _finite_number, check_enough_strides, iqr_outliers, window, window_times_s
from .gait import _where as _gait_where

__all__ = [
    "MATCH_COLUMNS",
    "COUNT_COLUMNS",
    "MIN_PAIRS_FOR_OUTLIERS",
    "too_short",
    "match_unperturbed",
    "paired_windows",
    "window_outliers",
    "subject_onset_response",
    "null_pair_windows",
]

log = logging.getLogger(__name__)

#: Columns of the table returned by :func:`match_unperturbed`.
MATCH_COLUMNS: tuple[str, ...] = (
    "stride", "onset_s", "toe_off_s", "matched_stride", "matched_anchor_s", "rmsd_rad", "n_candidates",
)
#: Columns of the counts table returned by :func:`subject_onset_response`.
COUNT_COLUMNS: tuple[str, ...] = (
    "trial", "n_perturbed", "n_too_short", "n_no_match", "n_outliers", "n_kept", "status", "reason",
)
#: Fewest pairs the IQR rule judges (:func:`loper_analysis.gait.iqr_outliers`); fewer are all kept.
MIN_PAIRS_FOR_OUTLIERS: int = 4

_TIME_TOL_S = 1e-9  # tolerance of time comparisons on exact quantities (grids, swing lengths)


# --------------------------------------------------------------------------- checks


# input checks shared with :mod:`.gait`
_where = _gait_where
_number = _finite_number


def _time(time_s, source: str) -> np.ndarray:
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 4:
        raise LoperInputError(f"{_where(source)}time_s must be 1-D with >= 4 frames, got shape {t.shape}")
    if not np.isfinite(t).all():
        i = int(np.flatnonzero(~np.isfinite(t))[0])
        raise LoperInputError(f"{_where(source)}time_s is not finite at frame {i}: {float(t[i])!r}")
    step = np.flatnonzero(np.diff(t) <= 0)
    if step.size:
        i = int(step[0]) + 1
        raise LoperInputError(
            f"{_where(source)}time_s must increase strictly; frame {i} ({float(t[i])!r} s) "
            f"follows {float(t[i - 1])!r} s"
        )
    return t


def _signal(name: str, values, n: int, source: str) -> np.ndarray:
    v = np.asarray(values, dtype=float)
    if v.ndim not in (1, 2) or v.shape[0] != n:
        raise LoperInputError(
            f"{_where(source)}{name} must have shape ({n},) or ({n}, k) like time_s, got {v.shape}"
        )
    return v


def _bool_column(table: pd.DataFrame, name: str, source: str) -> np.ndarray:
    col = table[name]
    if col.dtype == bool:
        return col.to_numpy()
    lookup = {True: True, False: False, "True": True, "False": False, "true": True, "false": False,
              1: True, 0: False, 1.0: True, 0.0: False}
    out = np.empty(len(col), dtype=bool)
    for i, value in enumerate(col.to_numpy()):
        try:
            out[i] = lookup[value]
        except (KeyError, TypeError):
            raise LoperInputError(
                f"{_where(source)}strides: column {name!r} must be boolean; stride row {i} holds {value!r}"
            ) from None
    return out


def _strides(strides, source: str, columns: Sequence[str]) -> pd.DataFrame:
    if not isinstance(strides, pd.DataFrame):
        raise LoperInputError(f"{_where(source)}strides must be a pandas DataFrame, got {type(strides).__name__}")
    missing = [c for c in columns if c not in strides.columns]
    if missing:
        raise LoperInputError(f"{_where(source)}strides: column(s) {missing} missing")
    return strides.reset_index(drop=True)


def _perturbed_onsets(table: pd.DataFrame, source: str) -> tuple[np.ndarray, np.ndarray]:
    """Perturbed mask and onsets; a perturbed stride needs a finite onset."""
    perturbed = _bool_column(table, "perturbed", source)
    onset = table["onset_s"].to_numpy(float)
    bad = np.flatnonzero(perturbed & ~np.isfinite(onset))
    if bad.size:
        i = int(bad[0])
        raise LoperInputError(
            f"{_where(source)}strides: perturbed stride {table['stride'].iloc[i]} has onset_s = {float(onset[i])!r}"
        )
    toe_off = table["toe_off_s"].to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(toe_off))
    if bad.size:
        i = int(bad[0])
        raise LoperInputError(
            f"{_where(source)}strides: stride {table['stride'].iloc[i]} has toe_off_s = {float(toe_off[i])!r}"
        )
    return perturbed, onset


def _span(start_s, end_s, source: str) -> tuple[float, float]:
    a = _number("start_s", start_s, source)
    b = _number("end_s", end_s, source)
    if not a <= 0.0 <= b:
        raise LoperInputError(
            f"{_where(source)}the window must hold the onset: start_s <= 0 <= end_s, got {a} .. {b} s"
        )
    return a, b


class _Sampler:
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


def _read_table(obj, what: str, name: str) -> tuple[pd.DataFrame, str]:
    """A table given as a DataFrame or a TSV path; returns it and the name to quote."""
    if isinstance(obj, pd.DataFrame):
        return obj, f"{name} ({what})"
    if isinstance(obj, (str, os.PathLike)):
        try:
            return pd.read_csv(obj, sep="\t"), str(obj)
        except (OSError, pd.errors.ParserError) as exc:
            raise LoperInputError(f"{obj}: cannot read the {what} table: {exc}") from None
    raise LoperInputError(f"{name}: {what} must be a DataFrame or a TSV path, got {type(obj).__name__}")


# --------------------------------------------------------------------------- too short


def too_short(strides: pd.DataFrame, onset_after_toe_off_s: float | None = None, window_after_s: float = 0.25,
              source: str = "") -> np.ndarray:
    """Perturbed strides whose swing is too short to hold the window after the onset.

    A perturbed stride is too short if ``swing_s < delay + window_after_s``,
    where ``delay`` is its own onset delay ``onset_s - toe_off_s`` (the
    window must end before the next heel strike) or, when
    ``onset_after_toe_off_s`` is given, the larger of the two (the study's
    rule: the 300 ms onset needs a swing of at least 550 ms). A swing of
    exactly the needed length is kept (1e-9 s tolerance). Unperturbed strides
    are never too short.

    Parameters
    ----------
    strides : pandas.DataFrame
        Stride table (:func:`loper_analysis.processing.cut_strides`): columns
        ``stride``, ``toe_off_s``, ``swing_s``, ``perturbed`` (bool) and
        ``onset_s`` (s, absolute; finite for perturbed strides).
    onset_after_toe_off_s : float, optional
        Nominal onset of the condition after toe-off, s (e.g. 0.3).
    window_after_s : float
        Length of the analysis window after the onset, s (>= 0).
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    numpy.ndarray of bool, shape (n_strides,)
        True for perturbed strides that are too short, in table order.

    Raises
    ------
    LoperInputError
        Missing columns, non-boolean flags, a perturbed stride without a
        finite onset, negative or non-finite settings.
    """
    table = _strides(strides, source, ("stride", "toe_off_s", "swing_s", "perturbed", "onset_s"))
    after = _number("window_after_s", window_after_s, source, minimum=0.0)
    perturbed, onset = _perturbed_onsets(table, source)
    delay = onset - table["toe_off_s"].to_numpy(float)
    if onset_after_toe_off_s is not None:
        delay = np.fmax(delay, _number("onset_after_toe_off_s", onset_after_toe_off_s, source, minimum=0.0))
    swing = table["swing_s"].to_numpy(float)
    with np.errstate(invalid="ignore"):
        short = swing < delay + after - _TIME_TOL_S
    return perturbed & short


# --------------------------------------------------------------------------- matching


def match_unperturbed(
    time_s,
    signals,
    strides: pd.DataFrame,
    before_s: float = 0.025,
    source: str = "",
    *,
    span_s: tuple[float, float] | None = None,
    onset_after_toe_off_s: float | None = None,
    window_after_s: float | None = None,
    candidate_within_swing: bool = False,
    missing: str = "raise",
    null_pairs: bool = False,
) -> pd.DataFrame:
    """For each perturbed stride, the unperturbed stride most similar just before the onset.

    Candidates are the strides of the same table (one trial) that are
    neither perturbed nor ``removed``. Candidate ``u`` is aligned to the
    perturbed stride ``p`` at ``anchor_u = toe_off_u + (onset_p - toe_off_p)``.
    The matching frames are the frames of ``p`` with
    ``onset_p - before_s <= time_s <= onset_p``; at their times relative to
    the onset the candidate is sampled by cubic spline, and the RMSD over
    these frames and all signals is taken. The candidate with the smallest
    RMSD wins (ties: the first in table order).

    A candidate is skipped when its aligned span ``anchor_u + span_s`` leaves
    the (finite) data, or - with ``candidate_within_swing`` - ends after its
    own heel strike (``end_s``). A perturbed stride whose own span leaves the
    data, or without any candidate, has no match.

    Parameters
    ----------
    time_s : array_like, shape (n_frames,)
        Frame times in s, strictly increasing.
    signals : array_like, shape (n_frames,) or (n_frames, k)
        Signals compared, usually hip, knee and ankle angles of the leg, rad.
        NaN policy: the matching frames of ``p`` must be finite; a candidate
        whose span touches non-finite frames is skipped.
    strides : pandas.DataFrame
        Stride table of the trial: ``stride``, ``toe_off_s``, ``end_s``,
        ``swing_s``, ``perturbed`` (bool), ``onset_s`` (s), ``removed`` (bool).
    before_s : float
        Matching span before the onset, s (>= 0).
    source : str
        Name of the trial, quoted in error messages and ``attrs``.
    span_s : (float, float), optional
        Span (start, end) relative to onset/anchor, s, that perturbed and
        candidate data must cover, e.g. ``(-0.125, 0.25)`` for the windows of
        :func:`paired_windows`; it is widened to hold ``-before_s .. 0``.
        Default ``(-before_s, 0)``.
    onset_after_toe_off_s, window_after_s : float, optional
        With ``window_after_s``, perturbed strides that are :func:`too_short`
        are left out (listed in ``attrs["too_short"]``).
    candidate_within_swing : bool
        Require the candidate's span to end before its own heel strike.
    missing : {"raise", "drop"}
        A perturbed stride without match raises, or is left out and listed in
        ``attrs["unmatched"]``.
    null_pairs : bool
        Match the *unperturbed* strides instead, each as if perturbed
        ``onset_after_toe_off_s`` after its toe-off, among the other
        candidates (never itself); perturbed strides take no part. Their
        differences are the stride-to-stride noise of a response
        (:func:`null_pair_windows`). Needs ``onset_after_toe_off_s``.

    Returns
    -------
    pandas.DataFrame
        One row per matched perturbed stride, in table order, columns
        :data:`MATCH_COLUMNS`: ``stride``, ``onset_s`` and ``toe_off_s`` of
        the perturbed stride (s), ``matched_stride``, ``matched_anchor_s``
        (s), ``rmsd_rad`` (RMSD in the signals' unit, rad for angles) and
        ``n_candidates`` (candidates that covered the span). ``attrs``:
        ``source``, ``before_s``, ``span_s``, ``too_short`` (list of stride
        numbers) and ``unmatched`` (dict stride number -> reason).

    Raises
    ------
    LoperInputError
        Bad time, shapes, settings or stride table; with ``missing="raise"`` a
        perturbed stride without match (naming the stride and ``source``).
    """
    t = _time(time_s, source)
    v = _signal("signals", signals, t.size, source)
    v2 = v.reshape(t.size, -1)
    cols = ["stride", "toe_off_s", "end_s", "swing_s", "perturbed", "onset_s", "removed"]
    table = _strides(strides, source, cols)
    before = _number("before_s", before_s, source, minimum=0.0)
    lo_span, hi_span = (-before, 0.0) if span_s is None else _span(*span_s, source)
    lo_span, hi_span = min(lo_span, -before), max(hi_span, 0.0)
    if missing not in ("raise", "drop"):
        raise LoperInputError(f"{_where(source)}missing must be 'raise' or 'drop', got {missing!r}")
    perturbed, onset = _perturbed_onsets(table, source)
    removed = _bool_column(table, "removed", source)
    if null_pairs:
        if onset_after_toe_off_s is None:
            raise LoperInputError(f"{_where(source)}null_pairs needs onset_after_toe_off_s")
        delay = _number("onset_after_toe_off_s", onset_after_toe_off_s, source, minimum=0.0)
        table = table.assign(onset_s=np.where(perturbed, np.nan, table["toe_off_s"].to_numpy(float) + delay),
                             perturbed=~perturbed & ~removed, removed=removed | perturbed)
        perturbed, onset = _perturbed_onsets(table, source)
        removed = _bool_column(table, "removed", source)
    short = (too_short(table, onset_after_toe_off_s, window_after_s, source) if window_after_s is not None
             else np.zeros(len(table), dtype=bool))
    stride_no = table["stride"].to_numpy()
    toe_off = table["toe_off_s"].to_numpy(float)
    end = table["end_s"].to_numpy(float)
    p = np.flatnonzero(perturbed & ~short)
    c = np.flatnonzero((null_pairs | ~perturbed) & ~removed)
    sampler = _Sampler(t, v2)
    tol = sampler.tol
    unmatched: dict[int, str] = {}

    # matching frames of each perturbed stride, padded to the longest
    onset_p, toe_p = onset[p], toe_off[p]
    first = np.searchsorted(t, onset_p - before - tol, side="left")
    count = np.searchsorted(t, onset_p + tol, side="right") - first
    m = max(int(count.max()) if p.size else 0, 1)
    valid = np.arange(m) < count[:, None]  # (np, m)
    idx = np.minimum(first[:, None] + np.arange(m), t.size - 1)
    rel = np.where(valid, t[idx] - onset_p[:, None], 0.0)
    vp = v2[idx]  # (np, m, k)
    own = sampler.run(onset_p + lo_span, onset_p + hi_span) >= 0
    own &= (count > 0) & np.where(valid[..., None], np.isfinite(vp), True).all(axis=(1, 2))
    for i in np.flatnonzero(~own):
        unmatched[int(stride_no[p[i]])] = (
            f"its window {onset_p[i] + lo_span:.4f} .. {onset_p[i] + hi_span:.4f} s leaves the finite data "
            f"({sampler.finite_spans()})"
        )

    # candidates aligned at the same time after their own toe-off
    anchors = toe_off[c][None, :] + (onset_p - toe_p)[:, None]  # (np, nc)
    ok = own[:, None] & (sampler.run(anchors + lo_span, anchors + hi_span) >= 0)
    if candidate_within_swing:
        ok &= anchors + hi_span <= end[c][None, :] + tol
    if null_pairs:
        ok &= p[:, None] != c[None, :]
    targets = anchors[:, :, None] + rel[:, None, :]  # (np, nc, m)
    sq = np.zeros(targets.shape)
    if ok.any():
        runs = sampler.run(anchors[ok] + lo_span, anchors[ok] + hi_span)
        vc = sampler(targets[ok], runs)  # (n_ok, m, k)
        diff = vc - np.broadcast_to(vp[:, None], ok.shape + vp.shape[1:])[ok]
        sq[ok] = np.sum(diff**2, axis=-1)
    n_values = np.maximum(count, 1)[:, None] * v2.shape[1]
    rmsd = np.where(ok, np.sqrt(np.sum(np.where(valid[:, None, :], sq, 0.0), axis=-1) / n_values), np.inf)
    best = np.argmin(rmsd, axis=1) if c.size else np.zeros(p.size, dtype=int)
    n_cand = ok.sum(axis=1)
    for i in np.flatnonzero(own & (n_cand == 0)):
        unmatched[int(stride_no[p[i]])] = (
            f"no unperturbed candidate among {c.size} (not perturbed, not removed) covers the aligned window"
            + (" inside its swing" if candidate_within_swing else "")
        )
    hit = own & (n_cand > 0)
    if unmatched and missing == "raise":
        s, why = next(iter(unmatched.items()))
        raise LoperInputError(f"{_where(source)}perturbed stride {s} has no unperturbed match: {why}")
    rows = np.flatnonzero(hit)
    out = pd.DataFrame({
        "stride": stride_no[p[rows]],
        "onset_s": onset_p[rows],
        "toe_off_s": toe_p[rows],
        "matched_stride": stride_no[c][best[rows]] if c.size else np.empty(0, dtype=stride_no.dtype),
        "matched_anchor_s": anchors[rows, best[rows]] if c.size else np.empty(0),
        "rmsd_rad": rmsd[rows, best[rows]] if c.size else np.empty(0),
        "n_candidates": n_cand[rows].astype(np.int64),
    }, columns=list(MATCH_COLUMNS))
    out.attrs.update({
        "source": source, "before_s": before, "span_s": (lo_span, hi_span),
        "too_short": [int(s) for s in stride_no[short]], "unmatched": unmatched,
    })
    return out


# --------------------------------------------------------------------------- windows


def paired_windows(
    time_s,
    columns: Mapping[str, object],
    matches: pd.DataFrame,
    start_s: float,
    end_s: float,
    rate_hz: float,
    *,
    method: str = "cubic",
    source: str = "",
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Perturbed and matched unperturbed windows of signals on one relative grid.

    The grid is ``gait.window_times_s(-start_s, end_s, rate_hz)`` - steps of
    ``1 / rate_hz`` s with the onset (t = 0) a grid point, e.g. 36 points for
    -25 .. 250 ms at 128 Hz. Pair ``i`` (row ``i`` of ``matches``) is sampled
    at ``onset_s + grid`` (perturbed) and ``matched_anchor_s + grid``
    (unperturbed).

    Parameters
    ----------
    time_s : array_like, shape (n_frames,)
        Frame times in s, strictly increasing.
    columns : mapping of str to array_like, shape (n_frames,) or (n_frames, k)
        Signals to window (any unit). NaN policy: each window must lie inside
        one run of finite frames of its signal.
    matches : pandas.DataFrame
        Columns ``stride``, ``onset_s`` and ``matched_anchor_s`` (s), e.g.
        from :func:`match_unperturbed`.
    start_s, end_s : float
        Window relative to the onset, s, ``start_s <= 0 <= end_s``
        (e.g. -0.125 for the 0.1 s initial-state span before a 25 ms window).
    rate_hz : float
        Grid rate, Hz.
    method : {"cubic", "linear"}
        Cubic spline (as in :func:`match_unperturbed`), or linear
        interpolation by :func:`loper_analysis.gait.window`.
    source : str
        Name of the trial, quoted in error messages.

    Returns
    -------
    dict of str to (numpy.ndarray, numpy.ndarray)
        Per column ``(perturbed, unperturbed)``, each of shape
        (n_pairs, n_grid) or (n_pairs, n_grid, k).

    Raises
    ------
    LoperInputError
        Bad shapes or settings, missing match columns, a window outside the
        (finite) data - naming the column, the stride and the window.
    """
    t = _time(time_s, source)
    start, end = _span(start_s, end_s, source)
    rate = _number("rate_hz", rate_hz, source)
    if rate <= 0:
        raise LoperInputError(f"{_where(source)}rate_hz must be positive, got {rate_hz!r}")
    if method not in ("cubic", "linear"):
        raise LoperInputError(f"{_where(source)}method must be 'cubic' or 'linear', got {method!r}")
    if not isinstance(matches, pd.DataFrame):
        raise LoperInputError(f"{_where(source)}matches must be a pandas DataFrame, got {type(matches).__name__}")
    need = [c for c in ("stride", "onset_s", "matched_anchor_s") if c not in matches.columns]
    if need:
        raise LoperInputError(f"{_where(source)}matches: column(s) {need} missing")
    anchors = {"perturbed": matches["onset_s"].to_numpy(float),
               "unperturbed": matches["matched_anchor_s"].to_numpy(float)}
    for what, a in anchors.items():
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise LoperInputError(
                f"{_where(source)}matches: stride {matches['stride'].iloc[int(bad[0])]} has a non-finite "
                f"{'onset_s' if what == 'perturbed' else 'matched_anchor_s'}"
            )
    grid = window_times_s(-start, end, rate)
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name, values in columns.items():
        v = _signal(f"column {name!r}", values, t.size, source)
        pair = []
        if method == "linear":
            for a in anchors.values():
                pair.append(window(t, v, a, -start, end, rate, source=f"{_where(source)}column {name!r}"))
            out[name] = (pair[0], pair[1])
            continue
        sampler = _Sampler(t, v)
        for what, a in anchors.items():
            targets = a[:, None] + grid
            runs = sampler.run(targets[:, 0], targets[:, -1])
            bad = np.flatnonzero(runs < 0)
            if bad.size:
                i = int(bad[0])
                raise LoperInputError(
                    f"{_where(source)}column {name!r}: the {what} window of stride {matches['stride'].iloc[i]} "
                    f"({targets[i, 0]:.4f} .. {targets[i, -1]:.4f} s) leaves the finite data "
                    f"({sampler.finite_spans()})"
                )
            pair.append(sampler(targets, runs).reshape(targets.shape + v.shape[1:]))
        out[name] = (pair[0], pair[1])
    return out


# --------------------------------------------------------------------------- outliers


def window_outliers(
    differences,
    rel_time_s,
    before_s: float = 0.025,
    after_s: float = 0.25,
    whisker: float = 1.5,
    max_fraction: float = 0.2,
    names: Sequence[str] = JOINTS,
    source: str = "",
) -> pd.DataFrame:
    """The IQR outlier rule on the analysis window of perturbed-minus-unperturbed pairs.

    Only samples with ``-before_s <= rel_time_s <= after_s`` count (DESIGN.md
    section 4); the rule is :func:`loper_analysis.gait.iqr_outliers`
    (``whisker`` x IQR per sample, pair removed if more than
    ``max_fraction`` of its samples are outlying for any signal). With fewer
    than :data:`MIN_PAIRS_FOR_OUTLIERS` pairs the rule cannot be applied:
    all pairs are kept, ``judged`` is False and ``reason`` says why.

    Parameters
    ----------
    differences : array_like, shape (n_pairs, n_grid, k)
        Perturbed minus matched unperturbed signals (rad for joint angles).
    rel_time_s : array_like, shape (n_grid,)
        Time of each grid sample relative to the onset, s.
    before_s, after_s : float
        Analysis window before and after the onset, s (>= 0).
    whisker, max_fraction : float
        Settings of :func:`loper_analysis.gait.iqr_outliers`.
    names : sequence of str
        Signal names (length k), default hip, knee, ankle.
    source : str
        Name of the subject/condition, quoted in messages.

    Returns
    -------
    pandas.DataFrame
        One row per pair (input order): ``pair`` (row index into
        ``differences``), ``fraction_outlying_<name>`` (0 .. 1, NaN when not
        judged), ``removed`` (bool), ``reason`` (str), ``judged`` (bool).
        ``attrs``: ``judged``, ``n_window_samples``, ``before_s``,
        ``after_s``, ``whisker``, ``max_fraction``, ``source``.

    Raises
    ------
    LoperInputError
        Bad shapes or settings, no grid sample inside the window, non-finite
        differences inside the window.
    """
    d = np.asarray(differences, dtype=float)
    rel = np.asarray(rel_time_s, dtype=float)
    if d.ndim != 3 or rel.ndim != 1 or d.shape[1] != rel.size:
        raise LoperInputError(
            f"{_where(source)}differences must have shape (n_pairs, n_grid, k) with n_grid = rel_time_s.size "
            f"({rel.size}), got {d.shape}"
        )
    names = [str(n) for n in names]
    if len(names) != d.shape[2]:
        raise LoperInputError(f"{_where(source)}names must hold {d.shape[2]} names, got {names!r}")
    before = _number("before_s", before_s, source, minimum=0.0)
    after = _number("after_s", after_s, source, minimum=0.0)
    w = _number("whisker", whisker, source, minimum=0.0)
    mf = _number("max_fraction", max_fraction, source, minimum=0.0)
    sel = (rel >= -before - _TIME_TOL_S) & (rel <= after + _TIME_TOL_S)
    if not sel.any():
        raise LoperInputError(
            f"{_where(source)}no sample of rel_time_s ({rel.min() if rel.size else 'empty'} .. "
            f"{rel.max() if rel.size else ''} s) lies in the window -{before} .. {after} s"
        )
    n = d.shape[0]
    judged = n >= MIN_PAIRS_FOR_OUTLIERS
    if judged:
        table = iqr_outliers(d[:, sel], w, mf, names=names, source=source).rename(columns={"stride": "pair"})
    else:
        bad = np.argwhere(~np.isfinite(d[:, sel]))
        if bad.size:
            raise LoperInputError(f"{_where(source)}differences are not finite at pair {bad[0][0]}, "
                                  f"window sample {bad[0][1]}")
        table = pd.DataFrame({"pair": np.arange(n, dtype=np.int64)})
        for name in names:
            table[f"fraction_outlying_{name}"] = np.full(n, np.nan)
        table["removed"] = np.zeros(n, dtype=bool)
        table["reason"] = f"not judged: {n} pair(s), the IQR rule needs >= {MIN_PAIRS_FOR_OUTLIERS}"
    table["judged"] = judged
    table.attrs = {"judged": judged, "n_window_samples": int(sel.sum()), "before_s": before, "after_s": after,
                   "whisker": w, "max_fraction": mf, "source": source}
    return table


# --------------------------------------------------------------------------- subject average


def _mean_sd(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean and SD (ddof 1) over axis 0; NaN where too few rows (no warnings)."""
    shape = a.shape[1:]
    mean = a.mean(axis=0) if a.shape[0] else np.full(shape, np.nan)
    sd = a.std(axis=0, ddof=1) if a.shape[0] >= 2 else np.full(shape, np.nan)
    return mean, sd


def _window_settings(trials, onset_ms, rate_hz, before_s, after_s, initial_span_s, side, source):
    """Checked settings of a subject's windows: onset (s), before, after, initial span, window start (s), grid."""
    onset_s = _number("onset_ms", onset_ms, source, minimum=0.0) / 1e3
    before = _number("before_s", before_s, source, minimum=0.0)
    after = _number("after_s", after_s, source, minimum=0.0)
    initial = _number("initial_span_s", initial_span_s, source, minimum=0.0)
    if side not in ("left", "right"):
        raise LoperInputError(f"{_where(source)}side must be 'left' or 'right', got {side!r}")
    if isinstance(trials, Mapping) or not len(trials):
        raise LoperInputError(f"{_where(source)}trials must be a non-empty sequence of trial mappings")
    start = -(initial + before)
    grid = window_times_s(-start, after, _number("rate_hz", rate_hz, source))
    return onset_s, before, after, initial, start, grid


def _trial_inputs(trial: Mapping, k: int, side: str):
    """Checked frame data of one trial: name, time, columns to window, stride table."""
    if not isinstance(trial, Mapping):
        raise LoperInputError(f"trial {k} must be a mapping with name, angles, strides, force, force_direction")
    name = str(trial.get("name", f"trial {k}"))
    missing = [key for key in ("angles", "strides", "force", "force_direction") if key not in trial]
    if missing:
        raise LoperInputError(f"{name}: trial input(s) {missing} missing")
    angles, where_a = _read_table(trial["angles"], "angles", name)
    strides, where_s = _read_table(trial["strides"], "strides", name)
    force, where_f = _read_table(trial["force"], "force", name)
    joints = [f"{j}_{side}_rad" for j in JOINTS]
    need = ["time_s", "pelvis_x_m", "pelvis_angle_rad", *joints]
    absent = [c for c in need if c not in angles.columns]
    if absent:
        raise LoperInputError(f"{where_a}: column(s) {absent} missing")
    t = _time(angles["time_s"].to_numpy(float), where_a)
    absent = [c for c in ("time_s", "force_measured_n") if c not in force.columns]
    if absent:
        raise LoperInputError(f"{where_f}: column(s) {absent} missing")
    tf = force["time_s"].to_numpy(float)
    if tf.shape != t.shape or not np.allclose(tf, t, rtol=0.0, atol=1e-6):
        raise LoperInputError(f"{where_f}: time_s ({tf.size} frames) differs from the angles' frames in {where_a} "
                              f"({t.size} frames)")
    direction = np.asarray(trial["force_direction"], dtype=float)
    if direction.shape != (t.size, 2):
        raise LoperInputError(f"{name}: force_direction must have shape ({t.size}, 2), got {direction.shape}")
    with np.errstate(invalid="ignore"):
        off = np.flatnonzero(np.abs(np.hypot(direction[:, 0], direction[:, 1]) - 1.0) > 1e-6)
    if off.size:
        i = int(off[0])
        raise LoperInputError(f"{name}: force_direction at frame {i} (t = {t[i]:.4f} s) is not a unit vector: "
                              f"{direction[i].tolist()}")
    magnitude = force["force_measured_n"].to_numpy(float)
    columns = {
        "joints": angles[joints].to_numpy(float),
        "pelvis_angle": angles["pelvis_angle_rad"].to_numpy(float),
        "pelvis_x": angles["pelvis_x_m"].to_numpy(float),
        "force": magnitude,
        "force_vector": magnitude[:, None] * direction,  # NaN frames stay NaN
    }
    return name, where_s, t, columns, strides


def subject_onset_response(
    trials: Sequence[Mapping],
    onset_ms: float,
    rate_hz: float = 128.0,
    before_s: float = 0.025,
    after_s: float = 0.25,
    initial_span_s: float = 0.1,
    whisker: float = 1.5,
    max_fraction: float = 0.2,
    min_strides: int = 5,
    *,
    side: str = "left",
    method: str = "cubic",
    candidate_within_swing: bool = False,
    source: str = "",
) -> tuple[pd.DataFrame, pd.DataFrame, dict]:
    """Mean perturbation response of one subject at one onset, over the subject's trials.

    Per trial: perturbed strides that are :func:`too_short` for ``onset_ms``
    and ``after_s`` are dropped; the others are matched within the trial
    (:func:`match_unperturbed` on hip, knee and ankle of ``side`` over
    ``before_s``; candidates must cover the whole window); windows from
    ``-(initial_span_s + before_s)`` to ``after_s`` around the onset are
    taken (:func:`paired_windows`). The pairs of all trials are pooled, judged
    by :func:`window_outliers` on ``-before_s .. after_s``, and the kept pairs
    averaged. Status ``too_few_strides`` (and a
    :class:`loper_analysis.gait.TooFewStridesWarning` for the total) when
    fewer than ``min_strides`` pairs are kept.

    Parameters
    ----------
    trials : sequence of mapping
        One per trial of this onset: ``name`` (str), ``angles`` (DataFrame or
        TSV path: ``time_s``, ``pelvis_x_m``, ``pelvis_angle_rad``,
        ``{hip,knee,ankle}_<side>_rad``), ``strides`` (stride table of
        ``side``: :func:`loper_analysis.processing.cut_strides`), ``force``
        (``time_s``, ``force_measured_n``; N along the rods, forward positive,
        same frames as the angles) and ``force_direction`` (array (n_frames,
        2): unit vector of the rod force, world x/y, per frame).
    onset_ms : float
        Nominal onset after toe-off, ms (e.g. 300).
    rate_hz : float
        Frame rate and grid rate, Hz.
    before_s, after_s : float
        Analysis window around the onset, s.
    initial_span_s : float
        Extra span before the analysis window, s (initial state of the fit).
    whisker, max_fraction : float
        IQR rule settings.
    min_strides : int
        Fewest kept pairs for an ``ok`` average.
    side : {"left", "right"}
        Swing leg of the joint-angle columns.
    method : {"cubic", "linear"}
        Interpolation of :func:`paired_windows`.
    candidate_within_swing : bool
        See :func:`match_unperturbed`.
    source : str
        Name of the subject, quoted in messages.

    Returns
    -------
    response : pandas.DataFrame
        One row per grid sample: ``time_s`` (relative to onset, s);
        ``{hip,knee,ankle}_rad_mean`` / ``_sd`` - perturbed minus matched
        unperturbed angle (rad, SD ddof 1); ``force_n_mean`` / ``force_n_sd``
        - perturbed minus unperturbed measured force (N);
        ``{joint}_perturbed_rad_mean``, ``{joint}_unperturbed_rad_mean``
        (rad); ``force_perturbed_n_mean``, ``force_unperturbed_n_mean`` (N);
        ``n_pairs`` (kept pairs); ``analysis_window`` (bool, inside
        ``-before_s .. after_s``). NaN where no (mean) or one (SD) pair is kept.
    counts : pandas.DataFrame
        Columns :data:`COUNT_COLUMNS`, one row per trial and a row ``total``:
        perturbed strides, too short, without match, outliers, kept pairs,
        ``status`` (``ok`` | ``too_few_strides``: ``n_kept < min_strides``) and
        ``reason``. ``attrs["pairs"]``: one row per pair (``trial``,
        ``stride``, ``matched_stride``, ``onset_s``, ``matched_anchor_s``,
        ``rmsd_rad``, ``removed``, ``reason``); ``attrs["outliers_judged"]``.
    series : dict
        Means over kept pairs on the grid, named like the arguments of
        :func:`loper_analysis.identification.prepare_window`: ``time_s``
        (n_grid,), ``onset_s`` (0.0), ``q_unperturbed`` / ``q_perturbed``
        (n_grid, 4): [pelvis_x (m), thigh, shank, foot (rad)] from
        :func:`loper_analysis.dynamics.segment_coordinates`,
        ``pelvis_angle_unperturbed_rad`` / ``pelvis_angle_perturbed_rad``
        (n_grid,), ``force_unperturbed_n`` / ``force_perturbed_n`` (n_grid, 2):
        ``force_measured_n * force_direction`` (N, world x/y); plus
        ``window_before_s``, ``window_after_s``, ``initial_state_span_s`` and
        ``n_pairs``. Arrays are NaN when no pair is kept.

    Raises
    ------
    LoperInputError
        Bad inputs or settings (naming the trial/file, column and value),
        duplicate trial names.
    """
    onset_s, before, after, initial, start, grid = _window_settings(
        trials, onset_ms, rate_hz, before_s, after_s, initial_span_s, side, source)
    min_n = int(_number("min_strides", min_strides, source, minimum=0.0))

    per_trial, pairs, windows = [], [], []
    for k, trial in enumerate(trials):
        name, where_s, t, columns, strides = _trial_inputs(trial, k, side)
        if any(rec["trial"] == name for rec in per_trial):
            raise LoperInputError(f"{_where(source)}trial name {name!r} appears twice; names must be unique")
        table = _strides(strides, where_s, ("stride", "toe_off_s", "swing_s", "perturbed", "onset_s"))
        n_perturbed = int(_bool_column(table, "perturbed", where_s).sum())
        n_short = int(too_short(table, onset_s, after, source=where_s).sum())
        matches = match_unperturbed(
            t, columns["joints"], table, before, source=where_s, span_s=(start, after),
            onset_after_toe_off_s=onset_s, window_after_s=after, candidate_within_swing=candidate_within_swing,
            missing="drop",
        )
        for s, why in matches.attrs["unmatched"].items():
            log.info("%s: perturbed stride %s has no match: %s", where_s, s, why)
        windows.append(paired_windows(t, columns, matches, start, after, rate_hz, method=method, source=where_s))
        pairs.append(matches.assign(trial=name))
        per_trial.append({"trial": name, "n_perturbed": n_perturbed, "n_too_short": n_short,
                          "n_no_match": len(matches.attrs["unmatched"])})

    win = {key: tuple(np.concatenate([w[key][i] for w in windows]) for i in range(2)) for key in windows[0]}
    joints_p, joints_u = win["joints"]
    label = f"{source} onset {onset_ms:g} ms" if source else f"onset {onset_ms:g} ms"
    verdict = window_outliers(joints_p - joints_u, grid, before, after, whisker, max_fraction, JOINTS, label)
    pair_columns = ["trial", "stride", "matched_stride", "onset_s", "matched_anchor_s", "rmsd_rad"]
    filled = [m[pair_columns] for m in pairs if len(m)]
    pair_table = (pd.concat(filled, ignore_index=True) if filled else pairs[0][pair_columns]).reset_index(drop=True)
    pair_table.attrs = {}
    pair_table = pair_table.assign(removed=verdict["removed"].to_numpy(), reason=verdict["reason"].to_numpy())
    keep = ~pair_table["removed"].to_numpy(bool)
    n_pairs = int(keep.sum())

    # counts
    judged = bool(verdict.attrs["judged"])
    rows = []
    for rec in per_trial:
        mine = pair_table["trial"].to_numpy() == rec["trial"]
        rows.append({**rec, "n_outliers": int((mine & ~keep).sum()), "n_kept": int((mine & keep).sum())})
    total = {key: sum(r[key] for r in rows) for key in ("n_perturbed", "n_too_short", "n_no_match", "n_outliers",
                                                         "n_kept")}
    rows.append({"trial": "total", **total})
    for r in rows:
        parts = []
        if r["n_kept"] < min_n:
            parts.append(f"{r['n_kept']} pair(s) kept, fewer than min_strides = {min_n}"
                         + ("" if r["trial"] == "total" else " (the average pools the trials: see total)"))
        if r["n_too_short"]:
            parts.append(f"{r['n_too_short']} too short (swing < onset delay + {after * 1e3:g} ms)")
        if r["n_no_match"]:
            parts.append(f"{r['n_no_match']} without unperturbed match")
        if r["n_outliers"]:
            parts.append(f"{r['n_outliers']} outlier(s) in the window -{before * 1e3:g} .. {after * 1e3:g} ms")
        if not judged:
            parts.append(verdict["reason"].iloc[0] if len(verdict) else "outliers not judged: no pair")
        r["status"] = "ok" if r["n_kept"] >= min_n else "too_few_strides"
        r["reason"] = "; ".join(parts)
    counts = pd.DataFrame(rows, columns=list(COUNT_COLUMNS))
    check_enough_strides(n_pairs, label or "perturbation response", min_n)
    counts.attrs = {"pairs": pair_table, "outliers_judged": judged, "onset_ms": float(onset_ms), "source": source}
    log.info("%s: %d perturbed, %d too short, %d without match, %d outliers, %d kept", label, total["n_perturbed"],
             total["n_too_short"], total["n_no_match"], total["n_outliers"], total["n_kept"])

    # averages over the kept pairs
    kept = {key: (p[keep], u[keep]) for key, (p, u) in win.items()}
    jp, ju = kept["joints"]
    d_mean, d_sd = _mean_sd(jp - ju)
    fp, fu = kept["force"]
    f_mean, f_sd = _mean_sd(fp - fu)
    jp_mean, ju_mean = _mean_sd(jp)[0], _mean_sd(ju)[0]
    response = pd.DataFrame({"time_s": grid})
    for j, joint in enumerate(JOINTS):
        response[f"{joint}_rad_mean"] = d_mean[:, j]
        response[f"{joint}_rad_sd"] = d_sd[:, j]
    response["force_n_mean"], response["force_n_sd"] = f_mean, f_sd
    for j, joint in enumerate(JOINTS):
        response[f"{joint}_perturbed_rad_mean"] = jp_mean[:, j]
        response[f"{joint}_unperturbed_rad_mean"] = ju_mean[:, j]
    response["force_perturbed_n_mean"], response["force_unperturbed_n_mean"] = _mean_sd(fp)[0], _mean_sd(fu)[0]
    response["n_pairs"] = n_pairs
    response["analysis_window"] = (grid >= -before - _TIME_TOL_S) & (grid <= after + _TIME_TOL_S)
    response.attrs = {"onset_ms": float(onset_ms), "n_pairs": n_pairs, "source": source, "before_s": before,
                      "after_s": after, "initial_span_s": initial}

    series: dict = {"time_s": grid.copy(), "onset_s": 0.0}
    for what, i in (("perturbed", 0), ("unperturbed", 1)):
        j, pel, x = kept["joints"][i], kept["pelvis_angle"][i], kept["pelvis_x"][i]
        q = segment_coordinates(j.reshape(-1, 3), pel.reshape(-1), x.reshape(-1)).reshape(j.shape[:2] + (4,))
        series[f"q_{what}"] = _mean_sd(q)[0]
        series[f"pelvis_angle_{what}_rad"] = _mean_sd(pel)[0]
        series[f"force_{what}_n"] = _mean_sd(kept["force_vector"][i])[0]
    series.update({"window_before_s": before, "window_after_s": after, "initial_state_span_s": initial,
                   "n_pairs": n_pairs})
    return response, counts, series


# --------------------------------------------------------------------------- null pairs


def null_pair_windows(
    trials: Sequence[Mapping],
    onset_ms: float,
    rate_hz: float = 128.0,
    before_s: float = 0.025,
    after_s: float = 0.25,
    initial_span_s: float = 0.1,
    whisker: float = 1.5,
    max_fraction: float = 0.2,
    *,
    side: str = "left",
    source: str = "",
) -> dict:
    """Unperturbed strides paired like perturbed ones: samples of a response's stride-to-stride noise.

    Every unperturbed stride of every trial is treated as if perturbed at
    ``onset_ms`` after its toe-off, matched by the study's rule among the
    other unperturbed strides of its trial (:func:`match_unperturbed` with
    ``null_pairs``), windowed like :func:`subject_onset_response` does and
    judged by the same IQR rule (:func:`window_outliers`). What its
    difference shows is what a perturbed-minus-matched difference holds
    besides the response: the residual of the matching. Trials need
    ``name``, ``angles`` and ``strides`` (DataFrame or TSV path, as for
    :func:`subject_onset_response`); they may include trials of other onsets
    and unperturbed walking.

    Returns
    -------
    dict
        ``time_s`` (n_grid,) relative to the onset (s); per kept pair
        ``q_perturbed``, ``q_unperturbed`` (n_pairs, n_grid, 4): [pelvis_x (m),
        thigh, shank, foot (rad)]; ``pelvis_angle_perturbed_rad``,
        ``pelvis_angle_unperturbed_rad`` (n_pairs, n_grid); ``n_pairs`` and
        ``n_outliers``.
    """
    onset_s, before, after, initial, start, grid = _window_settings(
        trials, onset_ms, rate_hz, before_s, after_s, initial_span_s, side, source)
    joints = [f"{j}_{side}_rad" for j in JOINTS]
    parts = []
    for k, trial in enumerate(trials):
        name = str(trial.get("name", f"trial {k}")) if isinstance(trial, Mapping) else f"trial {k}"
        if not isinstance(trial, Mapping) or any(key not in trial for key in ("angles", "strides")):
            raise LoperInputError(f"{_where(source)}{name}: a trial needs angles and strides")
        angles, where_a = _read_table(trial["angles"], "angles", name)
        strides, where_s = _read_table(trial["strides"], "strides", name)
        absent = [c for c in ("time_s", "pelvis_x_m", "pelvis_angle_rad", *joints) if c not in angles.columns]
        if absent:
            raise LoperInputError(f"{where_a}: column(s) {absent} missing")
        t = _time(angles["time_s"].to_numpy(float), where_a)
        columns = {"joints": angles[joints].to_numpy(float), "pelvis_angle": angles["pelvis_angle_rad"].to_numpy(float),
                   "pelvis_x": angles["pelvis_x_m"].to_numpy(float)}
        matches = match_unperturbed(t, columns["joints"], strides, before, source=where_s, span_s=(start, after),
                                    onset_after_toe_off_s=onset_s, window_after_s=after, missing="drop",
                                    null_pairs=True)
        parts.append(paired_windows(t, columns, matches, start, after, rate_hz, source=where_s))
    win = {key: tuple(np.concatenate([w[key][i] for w in parts]) for i in range(2)) for key in parts[0]}
    jp, ju = win["joints"]
    label = f"{source} null pairs, onset {onset_ms:g} ms" if source else f"null pairs, onset {onset_ms:g} ms"
    keep = ~window_outliers(jp - ju, grid, before, after, whisker, max_fraction, JOINTS, label)["removed"].to_numpy()
    out: dict = {"time_s": grid}
    for what, i in (("perturbed", 0), ("unperturbed", 1)):
        j, pel, x = (win[key][i][keep] for key in ("joints", "pelvis_angle", "pelvis_x"))
        out[f"q_{what}"] = segment_coordinates(j.reshape(-1, 3), pel.reshape(-1), x.reshape(-1)).reshape(
            j.shape[:2] + (4,))
        out[f"pelvis_angle_{what}_rad"] = pel
    out["n_pairs"], out["n_outliers"] = int(keep.sum()), int((~keep).sum())
    log.info("%s: %d null pairs kept, %d outliers", label, out["n_pairs"], out["n_outliers"])
    return out
