"""Where points lie relative to a force plate: horizontal distance outside it and height above it.

* :func:`plate_axes` - a plate's centre, horizontal axes and vertical from its corners;
* :func:`plate_offsets` - distance outside the plate's outline and height
  above its surface of points such as heel markers.

Positions in m; corners and points in one frame (any orientation: the
vertical is the plate's normal unless given). The corners may run either
way round the plate: that only flips the normal's sign, which the outline
test and the (unsigned) height do not depend on. With ``up`` (the frame's
up direction) the normal is turned along it and a plate more than 45 deg
from level is refused (:func:`loper_analysis.gait.grf.surface_normal`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from loper_analysis.checks import integer, where
from loper_analysis.errors import LoperInputError

__all__ = ["plate_axes", "plate_offsets"]


def plate_axes(
    corners_m, vertical_axis: int | None, source: str, up: Sequence[float] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Centre and axes of one plate.

    Parameters
    ----------
    corners_m : array_like, shape (4, 3)
        The plate's corners in m, in order around the plate (either way round).
    vertical_axis : {0, 1, 2} or None
        The vertical coordinate axis; None: the plate's normal (the cross
        product of its diagonals, turned so that its largest component is
        positive, or along ``up`` when given).
    source : str
        Name quoted in messages.
    up : array_like, shape (3,), optional
        The up direction in the frame of the corners (e.g. the model's +Y,
        :data:`loper_analysis.motion.markers.MODEL_UP`), used when ``vertical_axis``
        is None: the normal is turned along it, and a plate whose normal lies
        more than 45 deg from it is refused.

    Returns
    -------
    centre_m : numpy.ndarray, shape (3,)
        Mean of the corners, m.
    axes : numpy.ndarray, shape (3, 3)
        Rows u, v (unit vectors in the plate's horizontal plane, u along the
        first edge) and n (the vertical), right-handed.

    Raises
    ------
    LoperInputError
        Corners that are not finite (4, 3), enclose no area or whose first
        edge is vertical; a bad ``vertical_axis`` or ``up``; with ``up``, a
        plate more than 45 deg from level.
    """
    c = np.asarray(corners_m, dtype=float)
    if c.shape != (4, 3) or not np.isfinite(c).all():
        raise LoperInputError(f"{where(source)}corners_m must be a finite (4, 3) array, got shape {c.shape}")
    if vertical_axis is None:
        n = np.cross(c[2] - c[0], c[3] - c[1])  # the diagonals' cross product: twice the area along the normal
        size = float(np.linalg.norm(n))
        if size < 1e-12:
            raise LoperInputError(f"{where(source)}corners_m enclose no area: {c.tolist()}")
        if up is None:
            n = n / size
            n = n if n[np.argmax(np.abs(n))] > 0 else -n
        else:
            from loper_analysis.gait.grf import surface_normal

            n = surface_normal(c, source, up)
    else:
        axis = integer("vertical_axis", vertical_axis, source, minimum=0)
        if axis > 2:
            raise LoperInputError(f"{where(source)}vertical_axis must be 0, 1 or 2, got {vertical_axis!r}")
        n = np.eye(3)[axis]
    u = (c[1] - c[0]) - np.dot(c[1] - c[0], n) * n
    if np.linalg.norm(u) < 1e-12:
        raise LoperInputError(f"{where(source)}corners_m: the first edge is vertical or empty: {c.tolist()}")
    u = u / np.linalg.norm(u)
    return c.mean(axis=0), np.vstack([u, np.cross(n, u), n])


def plate_offsets(
    points_m, corners_m, vertical_axis: int | None = None, source: str = "", up: Sequence[float] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal distance outside a plate and height above it of points (heel markers).

    The horizontal plane is the plate's plane: the normal is inferred from
    the corners (the diagonals' cross product) or, with ``vertical_axis``,
    is that coordinate axis. Points and corners are projected onto that
    plane; the corners must outline a convex quadrilateral (any winding).

    Parameters
    ----------
    points_m : array_like, shape (k, 3) or (3,)
        Positions in m; NaN rows give NaN.
    corners_m : array_like, shape (4, 3)
        The plate's corners in m, in order around the plate.
    vertical_axis : {0, 1, 2} or None
        The vertical coordinate axis; None: the plate's normal.
    source : str
        Name quoted in messages.
    up : array_like, shape (3,), optional
        The up direction in the frame of the corners (see :func:`plate_axes`).

    Returns
    -------
    outside_m : numpy.ndarray, shape (k,)
        0 for a point over the plate, else its horizontal distance to the
        plate's outline (m).
    height_m : numpy.ndarray, shape (k,)
        Distance of the point from the plate's plane (m, unsigned).
    """
    centre, axes = plate_axes(corners_m, vertical_axis, source, up)
    p = np.atleast_2d(np.asarray(points_m, dtype=float))
    if p.ndim != 2 or p.shape[1] != 3:
        raise LoperInputError(f"{where(source)}points_m must have shape (k, 3), got {np.shape(points_m)}")
    q = (p - centre) @ axes.T  # plate coordinates: u, v, n
    c = (np.asarray(corners_m, dtype=float) - centre) @ axes[:2].T
    edge = np.roll(c, -1, axis=0) - c  # (4, 2)
    rel = q[:, None, :2] - c[None]  # (k, 4, 2)
    cross = edge[None, :, 0] * rel[..., 1] - edge[None, :, 1] * rel[..., 0]
    inside = np.all(cross >= 0, axis=1) | np.all(cross <= 0, axis=1)
    s = np.clip(np.sum(rel * edge, axis=2) / np.sum(edge * edge, axis=1), 0.0, 1.0)
    gap = np.linalg.norm(rel - s[..., None] * edge[None], axis=2).min(axis=1)
    outside = np.where(inside, 0.0, gap)
    finite = np.isfinite(p).all(axis=1)
    return np.where(finite, outside, np.nan), np.where(finite, np.abs(q[:, 2]), np.nan)
