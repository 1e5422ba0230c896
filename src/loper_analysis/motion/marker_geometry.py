"""Whose markers are these? A trial's marker geometry against the subject's model.

Markers on one body keep their distances: a walking trial recorded on the subject whose static trial scaled the
model shows, pair by pair, about the distances of the model's markers (placed on that static trial by the
scaling). A trial of another subject (a file copied into the wrong folder, a static trial of someone else) shows
distances that differ by the ratio of the two subjects' sizes, or by where the markers were put.

:func:`same_body_marker_pairs` lists the pairs and their model distances, :func:`marker_geometry` compares a
trial's distances with them (one row per pair), :func:`geometry_change` summarises the table as one number
(the median over pairs of the absolute relative change) and :func:`geometry_message` words a stop or a warning.
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
    "marker_geometry",
    "same_body_marker_pairs",
]

#: Shortest model distance of a pair compared (m): shorter pairs are dominated by noise and skin motion.
MIN_PAIR_DISTANCE_M: float = 0.05
#: Median absolute relative change of the pairs' distances above which a trial is warned about
#: (config ``markers.geometry_warn_change``).
GEOMETRY_WARN_CHANGE: float = 0.05
#: ... and above which the trial is refused as another subject's (config ``markers.geometry_stop_change``).
GEOMETRY_STOP_CHANGE: float = 0.08
#: Columns of :func:`marker_geometry`'s table.
GEOMETRY_COLUMNS = ("body", "marker_a", "marker_b", "n_frames", "model_distance_m", "trial_distance_m", "change")


def same_body_marker_pairs(model, labels: Sequence[str]) -> pd.DataFrame:
    """The pairs of a model's markers on one body that are among ``labels``, with their distance (m).

    Parameters
    ----------
    model : opensim.Model
        The subject's model (its markers placed on the subject, e.g. scaled to the static trial).
    labels : sequence of str
        The trial's marker names (model names).

    Returns
    -------
    pandas.DataFrame
        Columns ``body, marker_a, marker_b, model_distance_m``; pairs closer than :data:`MIN_PAIR_DISTANCE_M`
        left out.
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
                if d >= MIN_PAIR_DISTANCE_M:
                    rows.append({"body": body, "marker_a": a, "marker_b": b, "model_distance_m": d})
    return pd.DataFrame(rows, columns=["body", "marker_a", "marker_b", "model_distance_m"])


def marker_geometry(pairs: pd.DataFrame, markers_m: np.ndarray, labels: Sequence[str]) -> pd.DataFrame:
    """Each pair's distance in a trial (median over the frames holding both markers) against the model's.

    Parameters
    ----------
    pairs : pandas.DataFrame
        :func:`same_body_marker_pairs`.
    markers_m : ndarray, shape (n_frames, n_markers, 3)
        The trial's markers (m; NaN where missing).
    labels : sequence of str
        Names of the markers' second axis.

    Returns
    -------
    pandas.DataFrame
        :data:`GEOMETRY_COLUMNS`, one row per pair present in at least one frame; ``change`` is
        ``trial_distance_m / model_distance_m - 1``.
    """
    index = {name: j for j, name in enumerate(labels)}
    X = np.asarray(markers_m, float)
    rows = []
    for p in pairs.itertuples(index=False):
        d = np.linalg.norm(X[:, index[p.marker_a]] - X[:, index[p.marker_b]], axis=1)
        d = d[np.isfinite(d)]
        if not d.size:
            continue
        trial = float(np.median(d))
        rows.append(
            {
                "body": p.body,
                "marker_a": p.marker_a,
                "marker_b": p.marker_b,
                "n_frames": int(d.size),
                "model_distance_m": p.model_distance_m,
                "trial_distance_m": trial,
                "change": trial / p.model_distance_m - 1.0,
            }
        )
    return pd.DataFrame(rows, columns=list(GEOMETRY_COLUMNS))


def geometry_change(table: pd.DataFrame) -> float:
    """The median over pairs of the absolute relative change of :func:`marker_geometry` (NaN without pairs)."""
    return float(np.median(np.abs(table["change"]))) if len(table) else float("nan")


def geometry_message(table: pd.DataFrame, limit: float, setting: str, n_worst: int = 4) -> str:
    """Words for a trial whose geometry changed beyond ``limit``: the median change, the median ratio of the
    distances (a whole subject's size shows as a ratio common to every pair) and the ``n_worst`` pairs in mm."""
    change = geometry_change(table)
    ratio = float(np.median(table["trial_distance_m"] / table["model_distance_m"]))
    worst = table.reindex(table["change"].abs().sort_values(ascending=False).index).head(n_worst)
    pairs = ", ".join(
        f"{r.marker_a}-{r.marker_b} ({r.body}) {1e3 * r.trial_distance_m:.0f} mm against {1e3 * r.model_distance_m:.0f}"
        for r in worst.itertuples()
    )
    cause = (
        "Is this a recording of another subject, or the static trial of another subject?"
        if 2 / 3 < ratio < 3 / 2
        else f"The trial's distances are {ratio:.4g} times the model's: markers in another length unit (the file's "
        "POINT:UNITS), or the wrong model?"
    )
    return (
        f"the distances between markers on one body differ from the subject's model (scaled to its static trial) "
        f"by {100 * change:.1f} % in the median of {len(table)} pairs (limit {setting} {limit:g}; trial/model "
        f"ratio {ratio:.3f}): {pairs}. {cause}"
    )
