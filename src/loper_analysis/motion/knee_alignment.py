"""The lateral knee marker of a knee alignment device, as Plug-in Gait computes it.

A knee alignment device (KAD) is clamped to the knee in the static trial instead of the lateral knee
marker. Its three arms end in markers (``KAX`` on the flexion axis, ``KD1``, ``KD2``) and are mutually
perpendicular and of equal length ``a``, meeting at the device's origin, which rests on the lateral
femoral epicondyle. The three markers therefore form an equilateral triangle of side ``a * sqrt(2)``
and the origin is the apex of the right-angled corner above it: on the triangle's normal through its
centroid, at the height ``a / sqrt(3)``, on the side of the knee. That origin is the knee marker
(``KNE``) the static trial lacks.

The side of the knee is the side towards the body's midline: of the two points on the normal, the one
nearer the other leg's knee (or its device), else the pelvis markers' centre.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from loper_analysis.constants import SIDES
from loper_analysis.errors import LoperInputError

__all__ = ["kad_origin", "kad_knee_markers"]

_OTHER = {"left": "right", "right": "left"}


def kad_origin(kax, kd1, kd2, medial) -> np.ndarray:
    """The device's origin (n_frames, 3) from its markers (n_frames, 3 each, m; NaN where missing).

    Parameters
    ----------
    kax, kd1, kd2 : array-like
        The axis marker and the two others, (n_frames, 3) in m.
    medial : array-like
        A point towards the body's midline, (3,) or (n_frames, 3), m: picks the normal's side.

    Returns
    -------
    numpy.ndarray
        (n_frames, 3), m; NaN where a marker is missing.
    """
    A, B, C = (np.atleast_2d(np.asarray(v, float)) for v in (kax, kd1, kd2))
    side = (np.linalg.norm(A - B, axis=1) + np.linalg.norm(A - C, axis=1) + np.linalg.norm(B - C, axis=1)) / 3.0
    arm = side / np.sqrt(2.0)
    centroid = (A + B + C) / 3.0
    normal = np.cross(B - A, C - A)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    towards = np.broadcast_to(np.asarray(medial, float), centroid.shape) - centroid
    normal *= np.sign(np.sum(normal * towards, axis=1, keepdims=True))
    return centroid + normal * (arm / np.sqrt(3.0))[:, None]


def kad_knee_markers(
    names: Sequence[str], markers_m: np.ndarray, prefix: dict[str, str] | None = None, source: str = ""
) -> tuple[list[str], np.ndarray, list[str]]:
    """Add the knee marker of each side whose trial holds a knee alignment device but no knee marker.

    Parameters
    ----------
    names : sequence of str
        The trial's marker names (subject prefix stripped, label map applied).
    markers_m : numpy.ndarray
        (n_frames, n_markers, 3), m.
    prefix : dict, optional
        Side -> name prefix (default ``L`` and ``R``): the device is ``{prefix}KAX``, ``KD1``, ``KD2``, the
        knee marker ``{prefix}KNE``.
    source : str
        The file, for messages.

    Returns
    -------
    (list of str, numpy.ndarray, list of str)
        The names and markers with the knee markers appended, and the knee markers added.

    Raises
    ------
    LoperInputError
        A device whose markers are missing in every frame, or that lies on the body's midline (no side to
        tell), naming the file and the markers.
    """
    prefix = prefix or {"left": "L", "right": "R"}
    names = list(names)
    X = np.asarray(markers_m, float)
    index = {n: i for i, n in enumerate(names)}
    added = []
    for side in SIDES:
        kad = [f"{prefix[side]}{code}" for code in ("KAX", "KD1", "KD2")]
        knee = f"{prefix[side]}KNE"
        if knee in index or not all(m in index for m in kad):
            continue
        other = _OTHER[side]
        refs = [f"{prefix[other]}KNE", f"{prefix[other]}KAX"]
        refs = [r for r in refs if r in index] or [m for m in names if m.endswith(("ASI", "PSI", "SACR"))]
        if not refs:
            raise LoperInputError(
                f"{source}: knee alignment device {', '.join(kad)}: no other knee or pelvis marker tells its side"
            )
        medial = np.nanmean(np.stack([X[:, index[r]] for r in refs]), axis=0)
        origin = kad_origin(*(X[:, index[m]] for m in kad), medial)
        if not np.isfinite(origin).any():
            raise LoperInputError(f"{source}: knee alignment device {', '.join(kad)} missing in every frame")
        X = np.concatenate([X, origin[:, None, :]], axis=1)
        names.append(knee)
        index[knee] = len(names) - 1
        added.append(knee)
    return names, X, added
