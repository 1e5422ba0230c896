"""The walking direction of a trial, read from its markers, and the lab-to-model rotation chosen for it.

An overground lab records trials walked in both directions along its
walkway: one trial walks along the lab's +X, the next along -X. One fixed
lab-to-model rotation (``markers.lab_to_model_rotation_deg``) then turns
every other trial backwards in the model frame, and IK fails on it. Here
each trial's direction of travel is estimated from the markers themselves:

1. the configured rotation takes the lab into the model frame (Y up);
2. the markers' mean horizontal velocity (every marker, every pair of
   consecutive frames in which it is present) gives the direction of travel;
3. if the subject travels (mean speed at least ``min_speed_m_per_s``), a
   quarter turn about the vertical (0, 90, 180 or 270 degrees) is added so
   that the travel points along the model's +X (forward);
4. otherwise, when the trial's pelvis markers tell which way the subject
   faces (the anterior superior iliac spines in front of the posterior ones
   or the sacrum: :func:`facing_m`), the quarter turn that makes the subject
   face +X: a static trial faces the model's forward, as OpenSim's pelvis
   angles assume (its tilt, list and rotation mix for a subject facing the
   side); otherwise (a treadmill trial without pelvis markers) the
   configured rotation stands.

Quarter turns keep the lab's axes (force plates and walkway stay aligned
with the model's axes); the estimated direction is reported besides, so a
diagonal walk shows. The model frame is OpenSim's: X forward, Y up, Z to
the right; a heading of 0 degrees is travel along +X, 90 degrees along -Z
(counter-clockwise seen from above, the right-hand rule about +Y).
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.markers import rotate_markers

__all__ = ["HEADING_MODES", "TrialHeading", "facing_m", "travel_velocity_m_per_s", "trial_heading"]

#: ``auto``: each trial turned to walk along +X when it travels; ``fixed``: the configured rotation for every trial.
HEADING_MODES: tuple[str, ...] = ("auto", "fixed")
#: Mean horizontal marker speed (m/s) from which a trial counts as travelling
#: (config ``markers.min_travel_speed_m_per_s``).
MIN_TRAVEL_SPEED_M_PER_S: float = 0.25
#: Decimal places kept of the combined rotation's angles (degrees): exact quarter turns stay exact numbers.
_ANGLE_DECIMALS = 9


@dataclass(frozen=True)
class TrialHeading:
    """The rotation chosen for one trial.

    Attributes
    ----------
    rotation_deg : tuple of 3 floats
        Lab -> model rotation for this trial, degrees about the fixed X, Y, Z
        axes (:func:`loper_analysis.motion.markers.rotate_markers`).
    heading_deg : float
        Direction of travel in the model frame of the configured rotation,
        degrees about +Y (0 = +X, 180 = -X); NaN when the markers do not tell.
    speed_m_per_s : float
        Mean horizontal speed of the markers (m/s); NaN without two frames.
    turn_deg : float
        Quarter turn about the vertical added to the configured rotation (0, 90, 180 or 270).
    source : str
        ``travel`` (turned by the travel), ``pelvis`` (turned to face +X by the pelvis markers) or ``config``
        (the configured rotation stands).
    """

    rotation_deg: tuple[float, float, float]
    heading_deg: float
    speed_m_per_s: float
    turn_deg: float
    source: str


def travel_velocity_m_per_s(markers_m, rate_hz: float) -> np.ndarray:
    """Mean velocity (m/s, shape (3,)) of markers (n_frames, n_markers, 3) in m, NaN where missing.

    The mean runs over every marker and every pair of consecutive frames in
    which it is present; NaN if there is no such pair.
    """
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(f"markers_m must have shape (n_frames, n_markers, 3), got {X.shape}")
    if not np.isfinite(rate_hz) or rate_hz <= 0:
        raise LoperInputError(f"rate_hz must be positive, got {rate_hz}")
    step = np.diff(X, axis=0).reshape(-1, 3)
    step = step[np.all(np.isfinite(step), axis=1)]
    if not len(step):
        return np.full(3, np.nan)
    return step.mean(axis=0) * float(rate_hz)


def facing_m(markers_m, front: Sequence[int], back: Sequence[int]) -> np.ndarray:
    """Mean vector (3,) from the back pelvis markers' centre to the front ones' (m): the way the subject faces;
    NaN where the markers are missing throughout."""
    X = np.asarray(markers_m, dtype=float)
    if not len(front) or not len(back):
        return np.full(3, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN frames
        d = np.nanmean(X[:, list(front)], axis=1) - np.nanmean(X[:, list(back)], axis=1)
        return np.nanmean(d, axis=0)


def trial_heading(
    markers_lab_m,
    rate_hz: float,
    base_rotation_deg: Sequence[float],
    mode: str = "auto",
    min_speed_m_per_s: float = MIN_TRAVEL_SPEED_M_PER_S,
    source: str = "",
    pelvis: tuple[Sequence[int], Sequence[int]] | None = None,
) -> TrialHeading:
    """The lab -> model rotation of one trial (module docstring).

    Parameters
    ----------
    markers_lab_m : array_like
        Shape (n_frames, n_markers, 3), m, lab frame, NaN where missing.
    rate_hz : float
        Frame rate (Hz).
    base_rotation_deg : sequence of 3 floats
        The configured rotation (``markers.lab_to_model_rotation_deg``).
    mode : {"auto", "fixed"}
        ``markers.walking_direction``.
    min_speed_m_per_s : float
        Least mean horizontal speed (m/s) that counts as travel (``markers.min_travel_speed_m_per_s``).
    source : str
        The file, for messages.
    pelvis : (sequence of int, sequence of int), optional
        Indices of the front (ASIS) and back (PSIS, sacrum) pelvis markers: a trial that does not travel is
        turned to face +X by them.

    Returns
    -------
    TrialHeading
    """

    if mode not in HEADING_MODES:
        raise LoperInputError(
            f"{source or 'markers'}: markers.walking_direction must be one of {HEADING_MODES}, got {mode!r}"
        )
    base = tuple(float(a) for a in base_rotation_deg)
    v = travel_velocity_m_per_s(rotate_markers(markers_lab_m, base), rate_hz)
    speed = float(np.hypot(v[0], v[2]))
    heading = float(np.degrees(np.arctan2(-v[2], v[0]))) % 360.0 if np.isfinite(speed) and speed > 0 else np.nan
    if mode == "fixed":
        return TrialHeading(base, heading, speed, 0.0, "config")
    if not np.isfinite(speed) or speed < min_speed_m_per_s:
        face = facing_m(rotate_markers(markers_lab_m, base), *pelvis) if pelvis is not None else np.full(3, np.nan)
        if not np.all(np.isfinite(face)) or np.hypot(face[0], face[2]) < 0.05:
            return TrialHeading(base, heading, speed, 0.0, "config")
        facing = float(np.degrees(np.arctan2(-face[2], face[0]))) % 360.0
        return _turned(base, facing, heading, speed, "pelvis")
    return _turned(base, heading, heading, speed, "travel")


def _turned(base: tuple[float, float, float], direction_deg: float, heading: float, speed: float, source: str):
    """The heading with the quarter turn that brings ``direction_deg`` (about +Y) nearest to +X."""
    from scipy.spatial.transform import Rotation

    turn = float((-90.0 * round(direction_deg / 90.0)) % 360.0)
    if turn == 0.0:
        return TrialHeading(base, heading, speed, 0.0, source)
    combined = Rotation.from_euler("y", turn, degrees=True) * Rotation.from_euler("xyz", base, degrees=True)
    with warnings.catch_warnings():  # a quarter turn of a Z-up lab puts the middle angle at 90 deg ("gimbal lock"):
        warnings.simplefilter("ignore", UserWarning)  # the angles still give the rotation, only not uniquely
        euler = combined.as_euler("xyz", degrees=True)
    angles = np.round(euler, _ANGLE_DECIMALS) + 0.0  # + 0.0: no -0.0
    return TrialHeading((float(angles[0]), float(angles[1]), float(angles[2])), heading, speed, turn, source)
