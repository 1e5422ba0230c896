"""Whose markers are these? A walking trial's marker geometry against the subject's static trial.

Markers on one body keep their distances: a walking trial recorded on the subject of the static trial shows,
pair by pair, about the distances measured in that static trial. A trial of another subject (a file copied
into the wrong folder, a static trial of someone else) shows distances that differ by the ratio of the two
subjects' sizes, or by where the markers were put. Both are measured, so a model whose markers keep a
template's places (a children's Plug-in Gait pelvis 102 mm wide between the PSIS markers against the
template's 70) does not count. A subject without a static trial (a model given as it is) is compared with
its model's markers instead.

:func:`same_body_marker_pairs` lists the pairs (two markers on one body of the model) and their model
distances, :func:`marker_geometry` compares a trial's distances with the same pairs in the static trial, or
with the model's (one row per pair), :func:`geometry_change` summarises the table as one number (the median
over pairs of the absolute relative change), :func:`geometry_ratio` as the median ratio of the distances,
and :func:`geometry_message` words a stop or a warning.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

__all__ = [
    "GEOMETRY_COLUMNS",
    "GEOMETRY_STOP_CHANGE",
    "GEOMETRY_WARN_CHANGE",
    "MIN_PAIR_DISTANCE_M",
    "geometry_change",
    "geometry_message",
    "geometry_ratio",
    "marker_geometry",
    "same_body_marker_pairs",
]

#: Shortest reference distance of a pair compared (m): shorter pairs are dominated by noise and skin motion.
MIN_PAIR_DISTANCE_M: float = 0.05
#: Median absolute relative change of the pairs' distances above which a trial is warned about
#: (config ``ik.geometry_warn_change``).
GEOMETRY_WARN_CHANGE: float = 0.05
#: ... and above which the trial is refused as another subject's (config ``ik.geometry_stop_change``).
GEOMETRY_STOP_CHANGE: float = 0.08
#: Columns of :func:`marker_geometry`'s table.
GEOMETRY_COLUMNS = ("body", "marker_a", "marker_b", "n_frames", "reference_distance_m", "trial_distance_m", "change")


def same_body_marker_pairs(model, labels: Sequence[str], min_distance_m: float = MIN_PAIR_DISTANCE_M) -> pd.DataFrame:
    """The pairs of a model's markers on one body that are among ``labels``, with their distance (m).

    Parameters
    ----------
    model : opensim.Model
        The subject's model (which body carries each marker; its markers' places give ``model_distance_m``).
    labels : sequence of str
        The trial's marker names (model names).
    min_distance_m : float
        Pairs closer than this on the model (m) are left out (0: every pair, for a reference measured
        elsewhere, which :func:`marker_geometry` holds to :data:`MIN_PAIR_DISTANCE_M` itself).

    Returns
    -------
    pandas.DataFrame
        Columns ``body, marker_a, marker_b, model_distance_m``.
    """
    state = model.initSystem()
    markers = model.getMarkerSet()
    present = set(labels)
    by_body: dict[str, list[tuple[str, np.ndarray]]] = {}
    for i in range(markers.getSize()):
        m = markers.get(i)
        if m.getName() not in present:
            continue
        body = m.getParentFrame().findBaseFrame().getName()
        p = m.getLocationInGround(state)
        by_body.setdefault(body, []).append((m.getName(), np.array([p.get(0), p.get(1), p.get(2)])))
    rows = []
    for body, items in by_body.items():
        for i, (a, pa) in enumerate(items):
            for b, pb in items[i + 1 :]:
                d = float(np.linalg.norm(pa - pb))
                if d >= min_distance_m:
                    rows.append({"body": body, "marker_a": a, "marker_b": b, "model_distance_m": d})
    return pd.DataFrame(rows, columns=["body", "marker_a", "marker_b", "model_distance_m"])


def _pair_distance(X: np.ndarray, a: int, b: int) -> tuple[float, int]:
    """Median over the frames holding both markers of their distance (m; NaN without such a frame), and the
    number of those frames."""
    d = np.linalg.norm(X[:, a] - X[:, b], axis=1)
    d = d[np.isfinite(d)]
    return (float(np.median(d)), int(d.size)) if d.size else (float("nan"), 0)


def marker_geometry(
    pairs: pd.DataFrame,
    markers_m: np.ndarray,
    labels: Sequence[str],
    static_m: np.ndarray | None = None,
    static_labels: Sequence[str] | None = None,
) -> pd.DataFrame:
    """Each pair's distance in a trial (median over the frames holding both markers) against the same pair's
    in the static trial (``static_m`` given) or on the model.

    Parameters
    ----------
    pairs : pandas.DataFrame
        :func:`same_body_marker_pairs`.
    markers_m : ndarray, shape (n_frames, n_markers, 3)
        The trial's markers (m; NaN where missing).
    labels : sequence of str
        Names of the markers' second axis.
    static_m : ndarray, shape (n_static_frames, n_static_markers, 3), optional
        The subject's static trial (m, in the same model names; NaN where missing). Each pair's reference is
        then its median distance there; pairs with a marker the static trial lacks, or closer there than
        :data:`MIN_PAIR_DISTANCE_M`, are left out. None: the reference is the model's distance.
    static_labels : sequence of str, optional
        Names of ``static_m``'s second axis.

    Returns
    -------
    pandas.DataFrame
        :data:`GEOMETRY_COLUMNS`, one row per pair present in at least one frame of the trial (and of the
        static trial); ``change`` is ``trial_distance_m / reference_distance_m - 1``.
    """
    index = {name: j for j, name in enumerate(labels)}
    X = np.asarray(markers_m, float)
    if static_m is not None:
        static_index = {name: j for j, name in enumerate(static_labels or ())}
        S = np.asarray(static_m, float)
    rows = []
    for p in pairs.itertuples(index=False):
        if static_m is None:
            reference = float(p.model_distance_m)
        elif p.marker_a in static_index and p.marker_b in static_index:
            reference, _ = _pair_distance(S, static_index[p.marker_a], static_index[p.marker_b])
            if not reference >= MIN_PAIR_DISTANCE_M:  # NaN (never together) or too close
                continue
        else:
            continue
        trial, n = _pair_distance(X, index[p.marker_a], index[p.marker_b])
        if not n:
            continue
        rows.append(
            {
                "body": p.body,
                "marker_a": p.marker_a,
                "marker_b": p.marker_b,
                "n_frames": n,
                "reference_distance_m": reference,
                "trial_distance_m": trial,
                "change": trial / reference - 1.0,
            }
        )
    return pd.DataFrame(rows, columns=list(GEOMETRY_COLUMNS))


def geometry_change(table: pd.DataFrame) -> float:
    """The median over pairs of the absolute relative change of :func:`marker_geometry` (NaN without pairs)."""
    return float(np.median(np.abs(table["change"]))) if len(table) else float("nan")


def geometry_ratio(table: pd.DataFrame) -> float:
    """The median over pairs of trial distance / reference distance of :func:`marker_geometry` (1 without
    pairs): a whole subject's size, or a length unit, shows as a ratio common to every pair."""
    return float(np.median(table["trial_distance_m"] / table["reference_distance_m"])) if len(table) else 1.0


def geometry_message(
    table: pd.DataFrame, limit: float, setting: str, static_name: str | None = None, n_worst: int = 4
) -> str:
    """Words for a trial whose geometry changed beyond ``limit`` (config key ``setting``): the reference, the
    median change, the median ratio of the distances (:func:`geometry_ratio`) and the ``n_worst`` pairs in mm.

    ``static_name``: the static trial the table's references were measured in (its file, named); None: they
    are the model's markers (a subject without a static trial).
    """
    change, ratio = geometry_change(table), geometry_ratio(table)
    worst = table.reindex(table["change"].abs().sort_values(ascending=False).index).head(n_worst)
    if static_name is None:
        reference, short = "the subject's model's markers (no static trial to compare with)", "model"
    else:
        reference, short = f"the same pairs in the static trial {static_name}", "static"
    pairs = ", ".join(
        f"{r.marker_a}-{r.marker_b} ({r.body}) {1e3 * r.trial_distance_m:.0f} mm against "
        f"{1e3 * r.reference_distance_m:.0f}"
        for r in worst.itertuples()
    )
    if 2 / 3 < ratio < 3 / 2:
        cause = "Is this a recording of another subject, or the static trial of another subject?"
    elif static_name is None:
        cause = (
            f"The trial's distances are {ratio:.4g} times the model's: markers in another length unit (the file's "
            "POINT:UNITS), or the wrong model?"
        )
    else:
        cause = (
            f"The trial's distances are {ratio:.4g} times the static trial's: markers in another length unit "
            "(either file's POINT:UNITS)?"
        )
    return (
        f"the distances between markers on one body differ from {reference} by {100 * change:.1f} % in the "
        f"median of {len(table)} pairs (limit {setting} {limit:g}; trial/{short} ratio {ratio:.3f}): {pairs}. "
        f"{cause}"
    )
