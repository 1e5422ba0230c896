"""A check of a walking trial's feet from its markers: the heel markers lie on the sides they are given for
(:func:`heel_lateral_offset_m`).

Heel sides
    Along the pelvis's right axis (from a left pelvis marker to its right partner, ``LASI`` -> ``RASI``), the
    left heel lies left of the right heel: the mean over the trial of (left heel - right heel) projected on that
    axis is negative (-60 .. -173 mm on the seven clinical labs' walks and OpenSim's walking5). A positive mean
    says the heels given for the two feet are the other way round, or that a foot's marker was given for both.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["heel_lateral_offset_m"]


def _points(values, name: str) -> np.ndarray:
    X = np.asarray(values, dtype=float)
    if X.ndim != 2 or X.shape[1] != 3:
        raise LoperInputError(f"{name} must have shape (n_frames, 3), got {X.shape}")
    return X


def heel_lateral_offset_m(left_heel_m, right_heel_m, left_pelvis_m, right_pelvis_m) -> float:
    """Mean position of the left heel relative to the right heel along the pelvis's right axis.

    Parameters
    ----------
    left_heel_m, right_heel_m : array_like, shape (n, 3)
        The heel markers given for the left and the right foot, m, any frame fixed to the lab; NaN where missing.
    left_pelvis_m, right_pelvis_m : array_like, shape (n, 3)
        A left pelvis marker and its right partner (``LASI``, ``RASI``), m, same frame.

    Returns
    -------
    float
        Mean over the frames with all four markers of ``(left heel - right heel) . r``, ``r`` the unit vector from
        the left to the right pelvis marker, m: negative when the heels lie on their sides; NaN when no frame has
        all four.
    """
    L, R = _points(left_heel_m, "left_heel_m"), _points(right_heel_m, "right_heel_m")
    axis = _points(right_pelvis_m, "right_pelvis_m") - _points(left_pelvis_m, "left_pelvis_m")
    if not L.shape == R.shape == axis.shape:
        raise LoperInputError(f"the four markers must have one shape, got {L.shape}, {R.shape} and {axis.shape}")
    width = np.linalg.norm(axis, axis=1)
    ok = np.isfinite(L).all(axis=1) & np.isfinite(R).all(axis=1) & np.isfinite(width) & (width > 0)
    if not ok.any():
        return float("nan")
    lateral = np.sum((L[ok] - R[ok]) * axis[ok], axis=1) / width[ok]
    return float(np.mean(lateral))
