"""Matching each perturbed stride with the unperturbed stride of its trial that is most similar before the onset.

* :func:`too_short` - perturbed strides whose swing cannot hold the window;
* :func:`match_unperturbed` - the matched unperturbed stride and its anchor
  (also for null pairs: unperturbed strides matched as if perturbed);
  :func:`match_in_window` - the same for the windows of a subject's analysis grid.

Alignment: a candidate unperturbed stride ``u`` is aligned to a perturbed
stride ``p`` at the same time after its own toe-off,
``anchor_u = toe_off_u + (onset_p - toe_off_p)``; relative time 0 is the
onset in ``p`` and the anchor in ``u``. Times in s on the motion-capture
clock; angles in rad.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
import pandas as pd

from loper_analysis.checks import bool_column, number, require_columns, signal, time_vector, where
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.sampling import TIME_TOLERANCE_S, SplineSampler, window_span
from loper_analysis.impedance.responses.windows import WINDOW_AFTER_S, WINDOW_BEFORE_S, AnalysisGrid

__all__ = [
    "MATCH_COLUMNS",
    "STRIDE_TABLE_COLUMNS",
    "stride_table",
    "too_short",
    "match_unperturbed",
    "match_in_window",
]

#: Columns of the table returned by :func:`match_unperturbed`.
MATCH_COLUMNS: tuple[str, ...] = (
    "stride",
    "onset_s",
    "toe_off_s",
    "matched_stride",
    "matched_anchor_s",
    "rmsd_rad",
    "n_candidates",
)
#: Stride-table columns a response needs (:func:`loper_analysis.gait.strides.stride_tables`).
STRIDE_TABLE_COLUMNS: tuple[str, ...] = ("stride", "toe_off_s", "swing_s", "perturbed", "onset_s")


def stride_table(strides, source: str = "", columns: Sequence[str] = STRIDE_TABLE_COLUMNS) -> pd.DataFrame:
    """The stride table of a trial, checked to hold ``columns``, with a fresh index."""
    return require_columns(strides, columns, source, what="strides").reset_index(drop=True)


def _perturbed_onsets(table: pd.DataFrame, source: str) -> tuple[np.ndarray, np.ndarray]:
    """Perturbed mask and onsets; a perturbed stride needs a finite onset."""
    perturbed = bool_column(table, "perturbed", source, what="strides")
    onset = table["onset_s"].to_numpy(float)
    bad = np.flatnonzero(perturbed & ~np.isfinite(onset))
    if bad.size:
        i = int(bad[0])
        raise LoperInputError(
            f"{where(source)}strides: perturbed stride {table['stride'].iloc[i]} has onset_s = {float(onset[i])!r}"
        )
    toe_off = table["toe_off_s"].to_numpy(float)
    bad = np.flatnonzero(~np.isfinite(toe_off))
    if bad.size:
        i = int(bad[0])
        raise LoperInputError(
            f"{where(source)}strides: stride {table['stride'].iloc[i]} has toe_off_s = {float(toe_off[i])!r}"
        )
    return perturbed, onset


def too_short(
    strides: pd.DataFrame,
    onset_after_toe_off_s: float | None = None,
    window_after_s: float = WINDOW_AFTER_S,
    source: str = "",
) -> np.ndarray:
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
        Stride table (:func:`loper_analysis.gait.strides.stride_tables`): columns
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
    table = stride_table(strides, source, ("stride", "toe_off_s", "swing_s", "perturbed", "onset_s"))
    after = number("window_after_s", window_after_s, source, minimum=0.0)
    perturbed, onset = _perturbed_onsets(table, source)
    delay = onset - table["toe_off_s"].to_numpy(float)
    if onset_after_toe_off_s is not None:
        delay = np.fmax(delay, number("onset_after_toe_off_s", onset_after_toe_off_s, source, minimum=0.0))
    swing = table["swing_s"].to_numpy(float)
    with np.errstate(invalid="ignore"):
        short = swing < delay + after - TIME_TOLERANCE_S
    return perturbed & short


# --------------------------------------------------------------------------- matching


def match_unperturbed(
    time_s,
    signals,
    strides: pd.DataFrame,
    *,
    before_s: float = WINDOW_BEFORE_S,
    source: str = "",
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
    t = time_vector(time_s, source, min_count=4, item="frame")
    v = signal("signals", signals, t.size, source)
    v2 = v.reshape(t.size, -1)
    cols = ["stride", "toe_off_s", "end_s", "swing_s", "perturbed", "onset_s", "removed"]
    table = stride_table(strides, source, cols)
    before = number("before_s", before_s, source, minimum=0.0)
    lo_span, hi_span = (-before, 0.0) if span_s is None else window_span(*span_s, source)
    lo_span, hi_span = min(lo_span, -before), max(hi_span, 0.0)
    if missing not in ("raise", "drop"):
        raise LoperInputError(f"{where(source)}missing must be 'raise' or 'drop', got {missing!r}")
    perturbed, onset = _perturbed_onsets(table, source)
    removed = bool_column(table, "removed", source, what="strides")
    if null_pairs:
        table, perturbed, onset, removed = _as_null_pairs(table, perturbed, removed, onset_after_toe_off_s, source)
    short = (
        too_short(table, onset_after_toe_off_s, window_after_s, source)
        if window_after_s is not None
        else np.zeros(len(table), dtype=bool)
    )
    stride_no = table["stride"].to_numpy()
    toe_off = table["toe_off_s"].to_numpy(float)
    end = table["end_s"].to_numpy(float)
    p = np.flatnonzero(perturbed & ~short)
    c = np.flatnonzero((null_pairs | ~perturbed) & ~removed)
    sampler = SplineSampler(t, v2)
    tol = sampler.tol
    unmatched: dict[int, str] = {}

    onset_p, toe_p = onset[p], toe_off[p]
    frames = _matching_frames(t, v2, onset_p, before, tol)
    own = sampler.run(onset_p + lo_span, onset_p + hi_span) >= 0
    own &= (frames.count > 0) & np.where(frames.valid[..., None], np.isfinite(frames.values), True).all(axis=(1, 2))
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
    rmsd = _candidate_rmsd(sampler, anchors, ok, (lo_span, hi_span), frames)
    n_cand = ok.sum(axis=1)
    for i in np.flatnonzero(own & (n_cand == 0)):
        unmatched[int(stride_no[p[i]])] = (
            f"no unperturbed candidate among {c.size} (not perturbed, not removed) covers the aligned window"
            + (" inside its swing" if candidate_within_swing else "")
        )
    hit = own & (n_cand > 0)
    if unmatched and missing == "raise":
        s, why = next(iter(unmatched.items()))
        raise LoperInputError(f"{where(source)}perturbed stride {s} has no unperturbed match: {why}")
    out = _match_table(stride_no[p], stride_no[c], hit, onset_p, toe_p, anchors, rmsd, n_cand)
    out.attrs.update(
        {
            "source": source,
            "before_s": before,
            "span_s": (lo_span, hi_span),
            "too_short": [int(s) for s in stride_no[short]],
            "unmatched": unmatched,
        }
    )
    return out


def _as_null_pairs(
    table: pd.DataFrame,
    perturbed: np.ndarray,
    removed: np.ndarray,
    onset_after_toe_off_s: float | None,
    source: str,
) -> tuple[pd.DataFrame, np.ndarray, np.ndarray, np.ndarray]:
    """The stride table with the unperturbed strides as if perturbed ``onset_after_toe_off_s`` (s) after their
    toe-off and the perturbed ones removed, and its perturbed mask, onsets (s) and removed mask (each (n,))."""
    if onset_after_toe_off_s is None:
        raise LoperInputError(f"{where(source)}null_pairs needs onset_after_toe_off_s")
    delay = number("onset_after_toe_off_s", onset_after_toe_off_s, source, minimum=0.0)
    table = table.assign(
        onset_s=np.where(perturbed, np.nan, table["toe_off_s"].to_numpy(float) + delay),
        perturbed=~perturbed & ~removed,
        removed=removed | perturbed,
    )
    perturbed, onset = _perturbed_onsets(table, source)
    removed = bool_column(table, "removed", source, what="strides")
    return table, perturbed, onset, removed


class _Frames(NamedTuple):
    """The matching frames of each perturbed stride, padded to the longest (m frames).

    ``count`` (np,): frames of each; ``valid`` (np, m): the real ones; ``rel`` (np, m): their times relative to
    the onset (s; 0 for padding); ``values`` (np, m, k): the signals at them.
    """

    count: np.ndarray
    valid: np.ndarray
    rel: np.ndarray
    values: np.ndarray


def _matching_frames(t: np.ndarray, v2: np.ndarray, onset_p: np.ndarray, before: float, tol: float) -> _Frames:
    """The frames of ``t`` (s) from ``before`` (s) before each onset ``onset_p`` (np,) to it (``tol`` s of slack),
    with the signals ``v2`` (n_frames, k) there."""
    first = np.searchsorted(t, onset_p - before - tol, side="left")
    count = np.searchsorted(t, onset_p + tol, side="right") - first
    m = max(int(count.max()) if onset_p.size else 0, 1)
    valid = np.arange(m) < count[:, None]  # (np, m)
    idx = np.minimum(first[:, None] + np.arange(m), t.size - 1)
    rel = np.where(valid, t[idx] - onset_p[:, None], 0.0)
    return _Frames(count, valid, rel, v2[idx])


def _candidate_rmsd(
    sampler: SplineSampler, anchors: np.ndarray, ok: np.ndarray, span: tuple[float, float], frames: _Frames
) -> np.ndarray:
    """RMSD (np, nc) over the matching frames and signals between each perturbed stride and each candidate
    aligned at ``anchors`` (np, nc; s), sampled by cubic spline; inf where ``ok`` (np, nc) is False (the
    candidate's ``span`` (s) around its anchor leaves the data or it is not a candidate)."""
    lo_span, hi_span = span
    vp = frames.values  # (np, m, k)
    targets = anchors[:, :, None] + frames.rel[:, None, :]  # (np, nc, m)
    sq = np.zeros(targets.shape)
    if ok.any():
        runs = sampler.run(anchors[ok] + lo_span, anchors[ok] + hi_span)
        vc = sampler(targets[ok], runs)  # (n_ok, m, k)
        diff = vc - np.broadcast_to(vp[:, None], ok.shape + vp.shape[1:])[ok]
        sq[ok] = np.sum(diff**2, axis=-1)
    n_values = np.maximum(frames.count, 1)[:, None] * vp.shape[2]
    return np.where(ok, np.sqrt(np.sum(np.where(frames.valid[:, None, :], sq, 0.0), axis=-1) / n_values), np.inf)


def _match_table(
    perturbed_strides: np.ndarray,
    candidate_strides: np.ndarray,
    hit: np.ndarray,
    onset_p: np.ndarray,
    toe_p: np.ndarray,
    anchors: np.ndarray,
    rmsd: np.ndarray,
    n_cand: np.ndarray,
) -> pd.DataFrame:
    """The table of :func:`match_unperturbed` (:data:`MATCH_COLUMNS`): per perturbed stride with a match
    (``hit`` (np,)) the candidate of least ``rmsd`` (np, nc) and its anchor (``anchors`` (np, nc), s).

    ``perturbed_strides`` (np,), ``candidate_strides`` (nc,): the stride numbers; ``onset_p``, ``toe_p`` (np,):
    the perturbed strides' onsets and toe-offs (s); ``n_cand`` (np,): the candidates that covered the span.
    """
    best = np.argmin(rmsd, axis=1) if candidate_strides.size else np.zeros(perturbed_strides.size, dtype=int)
    rows = np.flatnonzero(hit)
    c_size = candidate_strides.size
    return pd.DataFrame(
        {
            "stride": perturbed_strides[rows],
            "onset_s": onset_p[rows],
            "toe_off_s": toe_p[rows],
            "matched_stride": candidate_strides[best[rows]] if c_size else np.empty(0, dtype=candidate_strides.dtype),
            "matched_anchor_s": anchors[rows, best[rows]] if c_size else np.empty(0),
            "rmsd_rad": rmsd[rows, best[rows]] if c_size else np.empty(0),
            "n_candidates": n_cand[rows].astype(np.int64),
        },
        columns=list(MATCH_COLUMNS),
    )


def match_in_window(
    time_s, signals, strides: pd.DataFrame, grid: AnalysisGrid, source: str = "", **options
) -> pd.DataFrame:
    """:func:`match_unperturbed` for the windows of a subject's analysis grid; strides without a match dropped.

    ``grid`` (:func:`loper_analysis.impedance.responses.windows.analysis_grid`): the match runs over
    ``grid.before_s`` before the onset; perturbed and candidate data must cover the windows
    ``grid.start_s .. grid.after_s`` around onset and anchor; a perturbed stride too short for
    ``grid.after_s`` after ``grid.onset_s`` is left out (:func:`too_short`). ``time_s``, ``signals``,
    ``strides`` and ``source`` as for :func:`match_unperturbed`; ``options``: its other keywords
    (``candidate_within_swing``, ``null_pairs``). Unmatched strides are listed in ``attrs["unmatched"]``.
    """
    return match_unperturbed(
        time_s,
        signals,
        strides,
        before_s=grid.before_s,
        source=source,
        span_s=(grid.start_s, grid.after_s),
        onset_after_toe_off_s=grid.onset_s,
        window_after_s=grid.after_s,
        missing="drop",
        **options,
    )
