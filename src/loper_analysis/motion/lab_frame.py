"""The lab's axes read from a recording: vertical axis, walking direction and the rotation into the model frame.

Used by ``loper-analysis inspect`` (:mod:`loper_analysis.inspection`) to
suggest ``markers.lab_to_model_rotation_deg`` for a lab. Markers are arrays
(n_frames, n_markers, 3) in m, lab frame, NaN where missing; force
platforms are :class:`~loper_analysis.io.force_platforms.ForcePlatform`
records (lab frame, SI units).

Lab axes (:func:`vertical_axis`, :func:`walking_direction`)
    The vertical axis comes from the force platforms when they tell it: the
    lab axis along the plates' normals (:func:`corner_normal`), pointing the
    way the largest force points (the force on the body points up while
    someone stands on a plate). Otherwise, and as a check, from the markers:
    the axis along which the markers of a frame spread most (feet to pelvis
    or head; the median over frames with at least 3 markers), pointing the
    way most coordinates lie (markers are above the floor). The walking
    direction is the horizontal axis of the largest travel (median over
    markers of the last minus the first present position) and its sign;
    less than ``min_travel_m`` on both horizontal axes is read as treadmill
    walking or standing.

Rotation into the model frame (:func:`lab_to_model_rotation_deg`)
    Three angles (degrees) about the fixed X, Y, Z axes as
    :func:`loper_analysis.motion.markers.rotate_markers` applies them. The
    suggestion is the smallest turn taking the lab's upward axis to
    OpenSim's +Y: Z-up lab -> ``(-90, 0, 0)``, Y-up lab -> ``(0, 0, 0)``.
    Given a walking direction as well, the rotation that also takes it to
    model +X (OpenSim's forward): among the triples of multiples of 90
    degrees doing that, the one with the fewest and smallest turns (Z-up
    lab walking -X -> ``(-90, 180, 0)``). The per-trial rotation of the
    pipeline, :func:`loper_analysis.motion.heading.trial_heading`, estimates travel
    differently (mean marker velocity) and may write the same rotation as
    another triple; this module's is the one the inspection prints.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from loper_analysis.checks import marker_array
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.markers import rotate_markers

if TYPE_CHECKING:  # records only; nothing is read here
    from loper_analysis.io.force_platforms import ForcePlatform

__all__ = [
    "AXIS_NAMES",
    "VerticalAxis",
    "WalkingDirection",
    "axis_name",
    "corner_normal",
    "lab_to_model_rotation_deg",
    "vertical_axis",
    "walking_direction",
]

#: Names of the lab axes 0, 1, 2.
AXIS_NAMES: tuple[str, str, str] = ("X", "Y", "Z")
#: Fewest markers in a frame whose spread tells the vertical (:func:`vertical_axis`).
_MIN_MARKERS_FOR_SPREAD = 3


@dataclass(frozen=True)
class VerticalAxis:
    """The lab's upward axis: ``sign`` (+1 or -1) times lab axis ``axis`` (0 X, 1 Y, 2 Z).

    ``basis`` says where the guess comes from (``"force platforms"``,
    ``"markers"`` or ``"assumed"``); ``marker_axis``/``marker_sign`` and
    ``marker_spread_m`` (median spread of a frame's markers along each lab
    axis, m, shape (3,)) are the markers' own answer (None without frames of
    at least 3 markers).
    """

    axis: int
    sign: int
    basis: str
    marker_axis: int | None = None
    marker_sign: int | None = None
    marker_spread_m: np.ndarray | None = None


@dataclass(frozen=True)
class WalkingDirection:
    """Where the markers travel: ``sign`` times lab axis ``axis``; axis None when they do not travel.

    ``travel_m`` (shape (3,), m) is the median over markers of the last minus
    the first present position; ``speed_m_per_s`` the median speed along
    ``axis`` (NaN when not travelling).
    """

    axis: int | None
    sign: int
    travel_m: np.ndarray
    speed_m_per_s: float


def axis_name(axis: int | None, sign: int = 1) -> str:
    """``"+Z"``, ``"-X"`` ...; ``"none"`` for axis None.

    Parameters
    ----------
    axis : int or None
        Lab axis (0 X, 1 Y, 2 Z), None when there is none.
    sign : int
        Its direction: ``"+"`` from 0 up, ``"-"`` below.

    Returns
    -------
    str
    """
    return "none" if axis is None else ("+" if sign >= 0 else "-") + AXIS_NAMES[axis]


def corner_normal(corners_m) -> np.ndarray:
    """Right-hand unit normal of a force platform's four corners in their order.

    ``(c3 - c1) x (c4 - c2)`` at unit length: it points down for corners
    listed clockwise seen from above (the C3D format's order, its plate z
    axis pointing down) and up for corners listed counter-clockwise.

    Parameters
    ----------
    corners_m : array_like
        Shape (4, 3), m, in file order.

    Returns
    -------
    numpy.ndarray
        Shape (3,), unit vector; all NaN when the corners enclose no area.

    Raises
    ------
    LoperInputError
        Corners not of shape (4, 3).
    """
    corners_m = np.asarray(corners_m, dtype=float)
    if corners_m.shape != (4, 3):
        raise LoperInputError(f"force platform: corners must have shape (4, 3), got {corners_m.shape}")
    n = np.cross(corners_m[2] - corners_m[0], corners_m[3] - corners_m[1])
    norm = float(np.linalg.norm(n))
    return n / norm if norm > 0 else np.full(3, np.nan)


def _plate_vertical(plate: ForcePlatform, min_load_n: float) -> tuple[int | None, int | None]:
    """(axis, sign) of one plate: axis along its normal, sign of its largest force along it (None: cannot tell)."""
    n = corner_normal(plate.corners_m)
    if not np.all(np.isfinite(n)) or np.max(np.abs(n)) < np.sqrt(0.5):
        return None, None
    axis = int(np.argmax(np.abs(n)))
    f = np.asarray(plate.force_n, dtype=float)[:, axis]
    if f.size == 0:
        return axis, None
    k = int(np.argmax(np.abs(f)))
    return axis, (int(np.sign(f[k])) if abs(f[k]) >= min_load_n else None)


def _marker_vertical(X: np.ndarray) -> tuple[int | None, int | None, np.ndarray | None]:
    """(axis, sign, median spread (3,) m) from the markers; Nones without frames of at least 3 markers."""
    present = np.all(np.isfinite(X), axis=2)
    frames = present.sum(axis=1) >= _MIN_MARKERS_FOR_SPREAD
    if not np.any(frames):
        return None, None, None
    Y = X[frames]
    spread = np.median(np.nanmax(Y, axis=1) - np.nanmin(Y, axis=1), axis=0)
    axis = int(np.argmax(spread))
    values = X[..., axis][present]
    return axis, (1 if np.median(values) >= 0 else -1), spread


def vertical_axis(markers_m, plates: Sequence[ForcePlatform] = (), min_load_n: float = 100.0) -> VerticalAxis:
    """Guess the lab's upward axis from the force platforms, else from the markers.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m, lab frame; NaN where missing.
    plates : sequence of ForcePlatform
        The file's platforms (lab frame); may be empty.
    min_load_n : float
        Smallest force magnitude (N) from which a plate's force tells which way is up.

    Returns
    -------
    VerticalAxis
        Axis and sign; the basis is ``"force platforms"`` when the plates
        agree on an axis (and tell its sign, or the markers do), else
        ``"markers"``, else ``"assumed"`` (+Z, the C3D habit).

    Raises
    ------
    LoperInputError
        ``markers_m`` not of shape (n_frames, n_markers, 3).
    """
    X = marker_array(markers_m)
    m_axis, m_sign, spread = _marker_vertical(X)
    answers = [_plate_vertical(p, min_load_n) for p in plates]
    axes = {a for a, _ in answers if a is not None}
    signs = {s for _, s in answers if s is not None}
    if len(axes) == 1:
        axis = axes.pop()
        if len(signs) == 1:
            return VerticalAxis(axis, signs.pop(), "force platforms", m_axis, m_sign, spread)
        if m_axis is not None:
            present = np.all(np.isfinite(X), axis=2)
            sign = 1 if np.median(X[..., axis][present]) >= 0 else -1
            return VerticalAxis(axis, sign, "force platforms", m_axis, m_sign, spread)
    if m_axis is not None:
        return VerticalAxis(m_axis, m_sign, "markers", m_axis, m_sign, spread)
    return VerticalAxis(2, 1, "assumed", None, None, None)


def walking_direction(markers_m, point_rate_hz: float, up_axis: int, min_travel_m: float = 0.5) -> WalkingDirection:
    """The horizontal axis and sign along which the markers travel, if they do.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m, lab frame; NaN where missing.
    point_rate_hz : float
        Frame rate (Hz).
    up_axis : int
        The lab's vertical axis (0, 1, 2), left out.
    min_travel_m : float
        Least travel (m) along a horizontal axis to count as walking through the lab.

    Returns
    -------
    WalkingDirection
        Axis None (treadmill or standing) when the median travel is below
        ``min_travel_m`` on both horizontal axes, or no marker is present twice.

    Raises
    ------
    LoperInputError
        Bad shape, rate or axis.
    """
    X = marker_array(markers_m)
    if up_axis not in (0, 1, 2):
        raise LoperInputError(f"markers: up_axis must be 0, 1 or 2, got {up_axis!r}")
    if not float(point_rate_hz) > 0:
        raise LoperInputError(f"markers: point_rate_hz must be positive, got {point_rate_hz!r}")
    present = np.all(np.isfinite(X), axis=2)
    shifts, durations = [], []
    for j in range(X.shape[1]):
        idx = np.flatnonzero(present[:, j])
        if idx.size >= 2:
            shifts.append(X[idx[-1], j] - X[idx[0], j])
            durations.append((idx[-1] - idx[0]) / float(point_rate_hz))
    if not shifts:
        return WalkingDirection(None, 0, np.full(3, np.nan), float("nan"))
    shifts, durations = np.array(shifts), np.array(durations)
    travel = np.median(shifts, axis=0)
    horizontal = [a for a in range(3) if a != up_axis]
    axis = max(horizontal, key=lambda a: abs(travel[a]))
    if abs(travel[axis]) < min_travel_m:
        return WalkingDirection(None, 0, travel, float("nan"))
    sign = 1 if travel[axis] > 0 else -1
    speed = float(np.median(np.abs(shifts[:, axis]) / durations))
    return WalkingDirection(axis, sign, travel, speed)


def lab_to_model_rotation_deg(
    up_axis: int, up_sign: int = 1, forward_axis: int | None = None, forward_sign: int = 1
) -> tuple[float, float, float]:
    """``markers.lab_to_model_rotation_deg`` taking the lab's up to OpenSim's +Y (and forward to +X).

    Parameters
    ----------
    up_axis, up_sign : int
        The lab's upward axis (0 X, 1 Y, 2 Z) and its sign (+1 or -1).
    forward_axis, forward_sign : int, optional
        The walking direction (another axis); None: only up is turned, by the smallest rotation.

    Returns
    -------
    tuple of 3 float
        Degrees about the fixed X, Y, Z axes (multiples of 90), as
        :func:`loper_analysis.motion.markers.rotate_markers` applies them: the
        triple with the fewest and smallest turns among those that do it.

    Raises
    ------
    LoperInputError
        An axis not 0, 1 or 2, a sign not +1 or -1, or forward along up.
    """
    if up_axis not in (0, 1, 2) or (forward_axis is not None and forward_axis not in (0, 1, 2)):
        raise LoperInputError(f"rotation: axes must be 0, 1 or 2, got up {up_axis!r}, forward {forward_axis!r}")
    if up_sign not in (1, -1) or forward_sign not in (1, -1):
        raise LoperInputError(f"rotation: signs must be +1 or -1, got {up_sign!r}, {forward_sign!r}")
    if forward_axis == up_axis:
        raise LoperInputError(f"rotation: the walking direction cannot be the vertical axis {AXIS_NAMES[up_axis]}")
    up = np.zeros(3)
    up[up_axis] = up_sign
    forward = None
    if forward_axis is not None:
        forward = np.zeros(3)
        forward[forward_axis] = forward_sign
    values = (0.0, -90.0, 90.0, 180.0)
    best, best_key = None, None
    for index in itertools.product(range(4), repeat=3):
        angles = tuple(values[i] for i in index)
        R = np.round(rotate_markers(np.eye(3), angles)).T  # rows p -> R @ p: the identity -> R.T
        if not np.allclose(R @ up, (0, 1, 0)):
            continue
        if forward is not None and not np.allclose(R @ forward, (1, 0, 0)):
            continue
        key = (
            0.0 if forward is not None else -np.trace(R),
            sum(a != 0 for a in angles),
            sum(abs(a) for a in angles),
            index,
        )
        if best_key is None or key < best_key:
            best, best_key = angles, key
    return tuple(float(a) + 0.0 for a in best)  # + 0.0: no -0.0
