"""Force-platform channels of a known load, for the tests' synthetic recordings: what a plate's six outputs read for
a force at a point, and the load read back from them (:func:`plate_load`).

The inverse of what C3D readers (ezc3d, OpenSim's ``C3DFileAdapter``) do with
the ``FORCE_PLATFORM`` group (:class:`loper_analysis.io.c3d_writer.ForcePlatform`):

1. The plate frame from the corners: x from corner 2 to corner 1, y from
   corner 4 to corner 1 (made orthogonal to x), z = x cross y; its centre is
   the mean of the corners (the centre of the working surface).
2. A ground reaction force ``F`` (on the subject, lab frame, N) at the centre
   of pressure ``P`` on the surface, with a free moment ``T`` about the
   surface normal (N·m, along the lab's +z for a plate in the floor), has the
   moment ``M_c = (P - c) x F + T n`` about the centre ``c``.
3. In plate coordinates (``f = R^T F``, ``m_c = R^T M_c``), the moment about
   the sensor origin is ``m_o = m_c - f x origin`` (``origin`` from the
   sensor origin to the surface centre, plate coordinates): readers add
   ``f x origin`` back.
4. TYPE 2 channels are ``(f, m_o)``, the moments in N times the point unit
   (N·mm); TYPE 4 channels are ``cal_matrix^-1 (f, m_o)``.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import LENGTH_UNITS_PER_M
from loper_analysis.io.c3d_writer import ForcePlatform

__all__ = ["plate_channels", "plate_frame", "plate_load", "wrench_channels"]


def plate_frame(plate: ForcePlatform) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (3, 3) whose columns are the plate's x, y, z axes in the lab frame, and the surface centre (3,) in m."""
    corners = np.asarray(plate.corners_m, dtype=float)
    x = corners[0] - corners[1]
    y = corners[0] - corners[3]
    z = np.cross(x, y)
    y = np.cross(z, x)
    R = np.column_stack([v / np.linalg.norm(v) for v in (x, y, z)])
    return R, corners.mean(axis=0)


def _rows(values, width: int, n: int | None, name: str) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim == 0 and width == 1:
        a = a.reshape(1, 1)
    if a.ndim == 1 and width > 1:
        a = a[np.newaxis]
    if a.ndim == 1:
        a = a[:, np.newaxis]
    if a.ndim != 2 or a.shape[1] != width or (n is not None and a.shape[0] not in (1, n)):
        raise LoperInputError(f"{name} must have shape (n, {width}), got {np.shape(values)}")
    return a


def wrench_channels(plate: ForcePlatform, force_n, moment_nm, point_unit: str = "mm") -> np.ndarray:
    """The six channel values (n, 6) of ``plate`` for a force (n, 3) N and a moment (n, 3) N·m about the
    centre of its working surface, both in the lab frame (channels are linear in both)."""
    if point_unit not in LENGTH_UNITS_PER_M:
        raise LoperInputError(f"point_unit must be one of {', '.join(LENGTH_UNITS_PER_M)}, got {point_unit!r}")
    F = _rows(force_n, 3, None, "force_n")
    M = np.broadcast_to(_rows(moment_nm, 3, F.shape[0], "moment_nm"), F.shape)
    if not (np.all(np.isfinite(F)) and np.all(np.isfinite(M))):
        raise LoperInputError("force_n and moment_nm must be finite")
    R, _ = plate_frame(plate)
    f, m_centre = F @ R, M @ R
    m_sensor = (m_centre - np.cross(f, np.asarray(plate.origin_m, dtype=float))) * LENGTH_UNITS_PER_M[point_unit]
    wrench = np.column_stack([f, m_sensor])
    if plate.type == 4:
        wrench = np.linalg.solve(np.asarray(plate.cal_matrix), wrench.T).T
    return wrench


def plate_channels(plate: ForcePlatform, force_n, cop_m, free_moment_nm=0.0, point_unit: str = "mm") -> np.ndarray:
    """The six channel values (n, 6) of ``plate`` for a force at a point.

    Parameters
    ----------
    plate : ForcePlatform
    force_n : array_like, shape (n, 3) or (3,)
        Ground reaction force on the subject, lab frame (N).
    cop_m : array_like, shape (n, 3) or (3,)
        Point of application (m, lab frame), on the working surface. Where the
        force is zero any finite point will do.
    free_moment_nm : array_like, shape (n,) or scalar
        Free moment about the plate's surface normal pointing up (lab +z for a
        plate in the floor), N·m.
    point_unit : {"mm", "cm", "m"}
        The file's point unit: moments are written in N times this unit.

    Returns
    -------
    numpy.ndarray, shape (n, 6)
        TYPE 2: Fx, Fy, Fz (N) and Mx, My, Mz (N·unit) about the sensor
        origin, plate coordinates; TYPE 4: those six through the inverse of
        ``cal_matrix``.
    """
    F = _rows(force_n, 3, None, "force_n")
    n = F.shape[0]
    P = np.broadcast_to(_rows(cop_m, 3, n, "cop_m"), (n, 3))
    T = np.broadcast_to(_rows(free_moment_nm, 1, n, "free_moment_nm")[:, 0], (n,))
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(T))):
        raise LoperInputError("cop_m and free_moment_nm must be finite")
    R, centre = plate_frame(plate)
    up = -R[:, 2] if R[2, 2] < 0 else R[:, 2]
    return wrench_channels(plate, F, np.cross(P - centre, F) + T[:, None] * up, point_unit)


def plate_load(plate: ForcePlatform, channels, point_unit: str = "mm") -> dict[str, np.ndarray]:
    """Force (n, 3) N, centre of pressure (n, 3) m and free moment (n,) N·m, lab frame, from the six channels
    (n, 6): the reading a C3D reader makes (the inverse of :func:`plate_channels`); the centre of pressure is NaN
    where the normal force is zero."""
    W = np.atleast_2d(np.asarray(channels, dtype=float))
    if plate.type == 4:
        W = W @ np.asarray(plate.cal_matrix).T
    f, m_sensor = W[:, :3], W[:, 3:] / LENGTH_UNITS_PER_M[point_unit]
    m_centre = m_sensor + np.cross(f, np.asarray(plate.origin_m, dtype=float))
    R, centre = plate_frame(plate)
    with np.errstate(divide="ignore", invalid="ignore"):
        cop_plate = np.column_stack([-m_centre[:, 1] / f[:, 2], m_centre[:, 0] / f[:, 2], np.zeros(len(f))])
    free = m_centre[:, 2] - (cop_plate[:, 0] * f[:, 1] - cop_plate[:, 1] * f[:, 0])
    sign = -1.0 if R[2, 2] < 0 else 1.0
    return {"force_n": f @ R.T, "cop_m": cop_plate @ R.T + centre, "free_moment_nm": sign * free}
