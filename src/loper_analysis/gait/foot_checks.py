"""Two checks of a walking trial's feet from its markers: the heel markers lie on the sides they are given for
(:func:`heel_lateral_offset_m`), and the frames run forward in time (:func:`toe_off_heel_lead_m`).

Heel sides
    Along the pelvis's right axis (from a left pelvis marker to its right partner, ``LASI`` -> ``RASI``), the
    left heel lies left of the right heel: the mean over the trial of (left heel - right heel) projected on that
    axis is negative (-60 .. -173 mm on the seven clinical labs' walks and OpenSim's walking5). A positive mean
    says the heels given for the two feet are the other way round, or that a foot's marker was given for both.

Time direction
    A foot leaves the ground toe last: at the end of a contact the heel has risen from the lowest it reached in
    that contact more than the toe has (by 10 .. 220 mm per contact on the real walks, the children's hospital's
    toe walker included: it lands toe first, but it also leaves toe last). Frames stored in reverse end each
    contact with the foot's landing, where a heel-first foot holds its heel down and its toe up: the heel's lead
    is negative (median -7 .. -59 mm on six of the same walks reversed). A reversed toe walker is not told (its
    landing is toe first too).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["heel_lateral_offset_m", "lower_foot", "toe_off_heel_lead_m"]


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


def toe_off_heel_lead_m(time_s, heel_height_m, toe_height_m, stances: Sequence[tuple[float, float]]) -> np.ndarray:
    """How much more the heel than the toe has risen at the end of each contact of one foot.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Marker frame times, s.
    heel_height_m, toe_height_m : array_like, shape (n,)
        The foot's heel and toe markers' heights along the vertical, m; NaN where missing.
    stances : sequence of (float, float)
        Each contact's start and end, s.

    Returns
    -------
    numpy.ndarray
        Shape (len(stances),), m: at the frame nearest the contact's end, the heel's height above its lowest in
        the contact minus the toe's above its own lowest; positive when the toe leaves last (time running
        forward). NaN for a contact with fewer than two frames or a marker missing at its end.
    """
    t = np.asarray(time_s, dtype=float)
    heel, toe = np.asarray(heel_height_m, dtype=float), np.asarray(toe_height_m, dtype=float)
    if t.ndim != 1 or heel.shape != t.shape or toe.shape != t.shape:
        raise LoperInputError(
            f"time_s, heel_height_m and toe_height_m must have one shape (n,), got {t.shape}, {heel.shape}, {toe.shape}"
        )
    out = np.full(len(stances), np.nan)
    for k, (start, end) in enumerate(stances):
        i0 = int(np.argmin(np.abs(t - start)))
        i1 = int(np.argmin(np.abs(t - end)))
        if i1 <= i0:
            continue
        h, s = heel[i0 : i1 + 1], toe[i0 : i1 + 1]
        if not (np.isfinite(h[-1]) and np.isfinite(s[-1])):
            continue
        out[k] = (h[-1] - np.nanmin(h)) - (s[-1] - np.nanmin(s))
    return out


def lower_foot(time_s, toe_height_m, start_s: float, end_s: float) -> str | None:
    """The foot whose toe was the lower over a contact (the standing foot), for a contact the heels did not assign.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Marker frame times, s.
    toe_height_m : mapping of str to array_like
        ``{"left": h, "right": h}``: each foot's toe height along the vertical, m, shape (n,); NaN where missing.
    start_s, end_s : float
        The contact's start and end, s.

    Returns
    -------
    str or None
        ``"left"`` or ``"right"``: the side whose toe's mean height over the contact's frames is the lower; None
        when a side has no frame there.
    """
    t = np.asarray(time_s, dtype=float)
    inside = (t >= start_s) & (t <= end_s)
    means = {}
    for side, h in toe_height_m.items():
        seen = np.asarray(h, dtype=float)[inside]
        seen = seen[np.isfinite(seen)]
        if not seen.size:
            return None
        means[side] = float(seen.mean())
    return min(means, key=means.get)
