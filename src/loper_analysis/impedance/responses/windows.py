"""Perturbed and matched unperturbed windows on one relative time grid, and the IQR rule on their differences.

* :func:`analysis_grid` - the checked window settings of a subject and onset and their grid;
* :func:`paired_windows` - windows of signals around onset and anchor; :func:`pooled_windows` -
  those of several trials as one; :func:`window_coordinates` - segment coordinates of joint-angle windows;
* :func:`window_outliers` - the IQR rule on the analysis window of the differences.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
import pandas as pd

from loper_analysis.checks import number, signal, time_vector, where
from loper_analysis.constants import JOINTS, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.outliers import (
    IQR_WHISKER,
    MAX_OUTLIER_FRACTION,
    MIN_STRIDES_FOR_OUTLIERS,
    MIN_VALID_STRIDES,
    iqr_outliers,
)
from loper_analysis.gait.resampling import window, window_times_s
from loper_analysis.impedance.responses.response_window import (
    INITIAL_STATE_SPAN_S,
    WINDOW_AFTER_S,
    WINDOW_BEFORE_S,
    ResponseWindow,
)
from loper_analysis.impedance.responses.sampling import TIME_TOLERANCE_S, SplineSampler, window_span
from loper_analysis.swing_leg.dynamics import segment_coordinates

__all__ = [
    "COUNTERFACTUALS",
    "INITIAL_STATE_SPAN_S",
    "WINDOW_AFTER_S",
    "WINDOW_BEFORE_S",
    "MIN_PAIRS_FOR_OUTLIERS",
    "ResponseSettings",
    "ResponseWindow",
    "AnalysisGrid",
    "analysis_grid",
    "paired_windows",
    "pooled_windows",
    "window_coordinates",
    "window_outliers",
]

#: The unperturbed reference of a perturbed stride (``impedance.counterfactual``): the study's one
#: matched stride, or the conditional mean over all unperturbed strides
#: (:mod:`loper_analysis.impedance.responses.conditional`).
COUNTERFACTUALS: tuple[str, ...] = ("matched_stride", "conditional")

#: Fewest pairs the IQR rule judges (:func:`loper_analysis.gait.outliers.iqr_outliers`); fewer are all kept.
MIN_PAIRS_FOR_OUTLIERS: int = MIN_STRIDES_FOR_OUTLIERS


@dataclass(frozen=True)
class ResponseSettings:
    """How the responses of a subject and onset are windowed, judged and averaged.

    ``rate_hz``: frame and grid rate (Hz); ``window``: the analysis window around the onset, preceded by
    the span for the fit's initial state (:class:`~loper_analysis.impedance.responses.response_window.ResponseWindow`);
    ``whisker`` and ``max_fraction`` are the IQR rule's
    (:func:`window_outliers`); ``min_strides`` the fewest kept pairs for an
    ``ok`` average; ``counterfactual`` the unperturbed reference of a perturbed
    stride: ``conditional`` (its own continuation predicted from all
    unperturbed strides, :mod:`loper_analysis.impedance.responses.conditional`) or
    ``matched_stride`` (the study's: the most similar unperturbed stride of
    its trial).
    """

    rate_hz: float = 128.0
    window: ResponseWindow = field(default_factory=ResponseWindow)
    whisker: float = IQR_WHISKER
    max_fraction: float = MAX_OUTLIER_FRACTION
    min_strides: int = MIN_VALID_STRIDES
    counterfactual: str = "conditional"

    def __post_init__(self):
        if self.counterfactual not in COUNTERFACTUALS:
            raise LoperInputError(
                f"impedance.counterfactual must be one of {', '.join(COUNTERFACTUALS)}, got {self.counterfactual!r}"
            )


class AnalysisGrid(NamedTuple):
    """The checked window settings of a subject and onset and their grid (:func:`analysis_grid`), in s.

    ``onset_s``: the nominal onset after toe-off; ``before_s``, ``after_s``: the analysis window
    around the onset; ``initial_state_span_s``: the span before it for the fit's initial state;
    ``start_s``: the windows' start relative to the onset, ``-(initial_state_span_s + before_s)``;
    ``time_s``: the relative time grid (:func:`loper_analysis.gait.resampling.window_times_s`).
    """

    onset_s: float
    before_s: float
    after_s: float
    initial_state_span_s: float
    start_s: float
    time_s: np.ndarray


def analysis_grid(trials, onset_ms, settings: ResponseSettings, side: str, source: str = "") -> AnalysisGrid:
    """Checked settings of a subject's windows and their grid (:class:`AnalysisGrid`).

    ``onset_ms`` (ms) and the windows of ``settings`` are checked, ``side`` must be a side and
    ``trials`` a non-empty sequence; ``source`` names the subject in messages.
    """
    if not isinstance(settings, ResponseSettings):
        raise LoperInputError(f"{where(source)}settings must be ResponseSettings, got {type(settings).__name__}")
    onset_s = number("onset_ms", onset_ms, source, minimum=0.0) / 1e3
    before = number("window_before_s", settings.window.before_s, source, minimum=0.0)
    after = number("window_after_s", settings.window.after_s, source, minimum=0.0)
    initial = number("initial_state_span_s", settings.window.initial_state_span_s, source, minimum=0.0)
    if side not in SIDES:
        raise LoperInputError(f"{where(source)}side must be 'left' or 'right', got {side!r}")
    if isinstance(trials, Mapping) or not len(trials):
        raise LoperInputError(f"{where(source)}trials must be a non-empty sequence of trial mappings")
    start = -(initial + before)
    grid = window_times_s(-start, after, number("rate_hz", settings.rate_hz, source))
    return AnalysisGrid(onset_s, before, after, initial, start, grid)


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

    The grid is ``loper_analysis.gait.resampling.window_times_s(-start_s, end_s, rate_hz)`` - steps of
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
        interpolation by :func:`loper_analysis.gait.resampling.window`.
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
    t = time_vector(time_s, source, min_count=4, item="frame")
    start, end = window_span(start_s, end_s, source)
    rate = number("rate_hz", rate_hz, source)
    if rate <= 0:
        raise LoperInputError(f"{where(source)}rate_hz must be positive, got {rate_hz!r}")
    if method not in ("cubic", "linear"):
        raise LoperInputError(f"{where(source)}method must be 'cubic' or 'linear', got {method!r}")
    if not isinstance(matches, pd.DataFrame):
        raise LoperInputError(f"{where(source)}matches must be a pandas DataFrame, got {type(matches).__name__}")
    need = [c for c in ("stride", "onset_s", "matched_anchor_s") if c not in matches.columns]
    if need:
        raise LoperInputError(f"{where(source)}matches: column(s) {need} missing")
    anchors = {
        "perturbed": matches["onset_s"].to_numpy(float),
        "unperturbed": matches["matched_anchor_s"].to_numpy(float),
    }
    for what, a in anchors.items():
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise LoperInputError(
                f"{where(source)}matches: stride {matches['stride'].iloc[int(bad[0])]} has a non-finite "
                f"{'onset_s' if what == 'perturbed' else 'matched_anchor_s'}"
            )
    grid = window_times_s(-start, end, rate)
    out: dict[str, tuple[np.ndarray, np.ndarray]] = {}
    for name, values in columns.items():
        v = signal(f"column {name!r}", values, t.size, source)
        pair = []
        if method == "linear":
            for a in anchors.values():
                pair.append(window(t, v, a, -start, end, rate, source=f"{where(source)}column {name!r}"))
            out[name] = (pair[0], pair[1])
            continue
        sampler = SplineSampler(t, v)
        for what, a in anchors.items():
            targets = a[:, None] + grid
            runs = sampler.run(targets[:, 0], targets[:, -1])
            bad = np.flatnonzero(runs < 0)
            if bad.size:
                i = int(bad[0])
                raise LoperInputError(
                    f"{where(source)}column {name!r}: the {what} window of stride {matches['stride'].iloc[i]} "
                    f"({targets[i, 0]:.4f} .. {targets[i, -1]:.4f} s) leaves the finite data "
                    f"({sampler.finite_spans()})"
                )
            pair.append(sampler(targets, runs).reshape(targets.shape + v.shape[1:]))
        out[name] = (pair[0], pair[1])
    return out


def pooled_windows(windows: Sequence[Mapping[str, tuple[np.ndarray, np.ndarray]]]) -> dict:
    """The windows of several trials (:func:`paired_windows` of each, same columns) as those of one.

    Per column ``(perturbed, unperturbed)``, each the trials' windows concatenated along the pairs
    (axis 0) in trial order.
    """
    return {key: tuple(np.concatenate([w[key][i] for w in windows]) for i in range(2)) for key in windows[0]}


def window_coordinates(joints_rad: np.ndarray, pelvis_angle_rad: np.ndarray, pelvis_x_m: np.ndarray) -> np.ndarray:
    """Segment coordinates (n_pairs, n_grid, 4) of windows: [pelvis_x (m), thigh, shank, foot (rad)].

    From the joint angles (n_pairs, n_grid, 3) in rad, the pelvis angle (n_pairs, n_grid) in rad and
    the pelvis x (n_pairs, n_grid) in m, sample by sample
    (:func:`loper_analysis.swing_leg.dynamics.segment_coordinates`).
    """
    q = segment_coordinates(joints_rad.reshape(-1, 3), pelvis_angle_rad.reshape(-1), pelvis_x_m.reshape(-1))
    return q.reshape(joints_rad.shape[:2] + (4,))


# --------------------------------------------------------------------------- outliers


def window_outliers(
    differences,
    rel_time_s,
    before_s: float = WINDOW_BEFORE_S,
    after_s: float = WINDOW_AFTER_S,
    whisker: float = IQR_WHISKER,
    max_fraction: float = MAX_OUTLIER_FRACTION,
    names: Sequence[str] = JOINTS,
    source: str = "",
) -> pd.DataFrame:
    """The IQR outlier rule on the analysis window of perturbed-minus-unperturbed pairs.

    Only samples with ``-before_s <= rel_time_s <= after_s`` count (the
    study's rule for perturbed strides); the rule is :func:`loper_analysis.gait.outliers.iqr_outliers`
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
        Settings of :func:`loper_analysis.gait.outliers.iqr_outliers`.
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
            f"{where(source)}differences must have shape (n_pairs, n_grid, k) with n_grid = rel_time_s.size "
            f"({rel.size}), got {d.shape}"
        )
    names = [str(n) for n in names]
    if len(names) != d.shape[2]:
        raise LoperInputError(f"{where(source)}names must hold {d.shape[2]} names, got {names!r}")
    before = number("before_s", before_s, source, minimum=0.0)
    after = number("after_s", after_s, source, minimum=0.0)
    w = number("whisker", whisker, source, minimum=0.0)
    mf = number("max_fraction", max_fraction, source, minimum=0.0)
    sel = (rel >= -before - TIME_TOLERANCE_S) & (rel <= after + TIME_TOLERANCE_S)
    if not sel.any():
        raise LoperInputError(
            f"{where(source)}no sample of rel_time_s ({rel.min() if rel.size else 'empty'} .. "
            f"{rel.max() if rel.size else ''} s) lies in the window -{before} .. {after} s"
        )
    n = d.shape[0]
    judged = n >= MIN_PAIRS_FOR_OUTLIERS
    if judged:
        table = iqr_outliers(d[:, sel], w, mf, names=names, source=source).rename(columns={"stride": "pair"})
    else:
        bad = np.argwhere(~np.isfinite(d[:, sel]))
        if bad.size:
            raise LoperInputError(
                f"{where(source)}differences are not finite at pair {bad[0][0]}, window sample {bad[0][1]}"
            )
        table = pd.DataFrame({"pair": np.arange(n, dtype=np.int64)})
        for name in names:
            table[f"fraction_outlying_{name}"] = np.full(n, np.nan)
        table["removed"] = np.zeros(n, dtype=bool)
        table["reason"] = f"not judged: {n} pair(s), the IQR rule needs >= {MIN_PAIRS_FOR_OUTLIERS}"
    table["judged"] = judged
    table.attrs = {
        "judged": judged,
        "n_window_samples": int(sel.sum()),
        "before_s": before,
        "after_s": after,
        "whisker": w,
        "max_fraction": mf,
        "source": source,
    }
    return table
