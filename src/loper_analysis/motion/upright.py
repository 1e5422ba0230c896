"""Which way is up for the markers of a standing or walking subject, in the model's frame after the lab-to-model
rotation: the direction from the feet to the pelvis (:func:`markers_up`).

A rotation of the wrong sign (``[90, 0, 0]`` for a Z-up lab, whose ``[-90, 0, 0]`` turns its +Z into the model's
+Y) hangs the subject below the floor: its pelvis lies along the model's -Y from its feet, and every joint angle,
ground reaction and event that follows is computed on an upside-down body. The angle between the markers' up and
the model's +Y is 0.4 .. 4.4 deg on every real static and walk with its lab's rotation (a walking trunk leans a
few degrees); the quarter turns a rotation can be wrong by give 90 or 180 deg. The limits lie halfway, where the
nearest axis of the model changes: beyond :data:`MAX_TILT_DEG` the subject lies (its up nearest a horizontal
axis), beyond :data:`MAX_UPSIDE_DOWN_DEG` it hangs upside down (nearest -Y).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["MAX_TILT_DEG", "MAX_UPSIDE_DOWN_DEG", "MIN_AGREEMENT", "markers_up", "nearest_axis", "upright_rotation_deg"]

#: Largest angle (deg) between the markers' up (:func:`markers_up`) and the model's +Y: beyond it another axis of
#: the model is nearer to the markers' up.
MAX_TILT_DEG = 45.0
#: Beyond this angle (deg) from the model's +Y the markers' up is nearest the model's -Y: the subject hangs upside
#: down.
MAX_UPSIDE_DOWN_DEG = 135.0
#: Least agreement of the frames' feet-to-pelvis directions (:func:`markers_up`'s third value) for the markers to
#: be judged as a body: 0.990 .. 1.000 on every real static and walk (a spread of about 8 deg RMS at most); points
#: at random give about ``1 / sqrt(n_frames)``. 0.9 is a spread of about 26 deg RMS.
MIN_AGREEMENT = 0.9

_AXES = {"+X": (1, 0, 0), "-X": (-1, 0, 0), "+Y": (0, 1, 0), "-Y": (0, -1, 0), "+Z": (0, 0, 1), "-Z": (0, 0, -1)}


def markers_up(markers_m, upper: Sequence[int], lower: Sequence[int]) -> tuple[np.ndarray, int, float]:
    """The markers' up: the mean over the frames of the unit vector from the lower markers' centre to the upper
    ones' centre.

    Parameters
    ----------
    markers_m : array_like, shape (n_frames, n_markers, 3)
        Marker positions, m, in the frame to judge (the model's, Y up); NaN where missing.
    upper, lower : sequence of int
        Indices of the upper markers (the pelvis's) and of the lower ones (the feet's); each frame's centre is the
        mean of those present.

    Returns
    -------
    (numpy.ndarray, int, float)
        The unit vector (3,) (NaN when no frame holds an upper and a lower marker), the number of frames that
        gave it, and the length of the frames' mean unit vector before it is normalised (1 when every frame
        points the same way, about ``1 / sqrt(n)`` for directions at random: points that are no body).
    """
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(f"markers_m must have shape (n_frames, n_markers, 3), got {X.shape}")
    if not len(upper) or not len(lower):
        return np.full(3, np.nan), 0, float("nan")

    def centre(idx):
        part = X[:, list(idx), :]
        seen = np.isfinite(part).all(axis=2)
        n = seen.sum(axis=1)
        total = np.where(seen[..., None], part, 0.0).sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return total / n[:, None]

    d = centre(upper) - centre(lower)
    length = np.linalg.norm(d, axis=1)
    ok = np.isfinite(length) & (length > 0)
    if not ok.any():
        return np.full(3, np.nan), 0, float("nan")
    mean = (d[ok] / length[ok, None]).mean(axis=0)
    agreement = float(np.linalg.norm(mean))
    return mean / agreement, int(ok.sum()), agreement


def nearest_axis(direction) -> str:
    """The model axis (``"+X"``, ``"-Y"``, ...) nearest to a direction (3,)."""
    v = np.asarray(direction, dtype=float)
    return max(_AXES, key=lambda k: float(np.dot(_AXES[k], v)))


def upright_rotation_deg(rotation_deg: Sequence[float], up_axis: str) -> tuple[float, float, float]:
    """The lab-to-model rotation (deg about the fixed X, Y, Z axes, as
    :func:`loper_analysis.motion.markers.rotate_markers`) that turns what ``rotation_deg`` puts along the model axis
    ``up_axis`` onto the model's +Y: the shortest turn between the two axes (about X for +-Z, about Z for +-X,
    half a turn about X for -Y) after ``rotation_deg``.

    Returns
    -------
    tuple of 3 float
        Degrees, each in (-180, 180], round-off below 1e-9 deg set to 0.
    """
    from scipy.spatial.transform import Rotation

    fix = {
        "+Y": Rotation.identity(),
        "-Y": Rotation.from_euler("x", 180, degrees=True),
        "+Z": Rotation.from_euler("x", -90, degrees=True),
        "-Z": Rotation.from_euler("x", 90, degrees=True),
        "+X": Rotation.from_euler("z", 90, degrees=True),
        "-X": Rotation.from_euler("z", -90, degrees=True),
    }[up_axis]
    angles = (fix * Rotation.from_euler("xyz", rotation_deg, degrees=True)).as_euler("xyz", degrees=True)
    angles = np.where(np.abs(angles) < 1e-9, 0.0, angles)
    angles = np.where(np.isclose(angles, -180.0), 180.0, angles)
    return tuple(float(a) for a in np.round(angles, 9))
