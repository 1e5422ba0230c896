"""Whether a trial is level walking: its pelvis neither rises nor falls over the trial, its force plates lie at
one height.

A trial on stairs or a ramp, or over plates set at different heights, is no level walk: its speed and angles
are not those of level walking. Two figures decide, each against a limit set from the level walks of seven
clinical labs, OpenSim's walking5 and Rajagopal2016's walk:

* :func:`pelvis_height_change_m` - the largest rise or fall of the pelvis over the trial: each pelvis marker's
  height (ASIS, PSIS or sacrum after the label map) averaged over :data:`HEIGHT_AVERAGE_S` (about one stride:
  the pelvis rises and falls 30 .. 57 mm within each stride), the signed change from its lowest to its highest
  mean (positive: rising), the median over the markers. Measured on the level walks: -4.6 mm (AUC), +7.5
  (FMC), +15.4 (MH), -0.2 (QCMAS), -10.9 (RBWH), -9.4 (RCH), +0.5 (SYD), -5.7 (walking5), -5.9
  (Rajagopal2016). The limit :data:`MAX_PELVIS_CHANGE_M` (0.075 m) is half a common stair riser (0.15 m;
  building codes allow risers of 0.10 .. 0.19 m), five times the largest level walk's.
* :func:`plate_heights_m` - each plate's height: the mean of its corners along the lab's up. Measured: AUC's
  two plates at -22.3 and -24.2 mm (1.8 mm apart), RCH's six within 1.4 mm, FMC's, MH's, QCMAS's, RBWH's and
  SYD's at 0. The limit :data:`MAX_PLATE_HEIGHT_RANGE_M` (0.01 m) is five times AUC's spread and a tenth of
  the lowest riser.

:func:`level_walking_warning` words the warning (empty for a level walk). Arrays in, SI units.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from loper_analysis.motion.label_matching import landmark_indices

__all__ = [
    "HEIGHT_AVERAGE_S",
    "MAX_PELVIS_CHANGE_M",
    "MAX_PLATE_HEIGHT_RANGE_M",
    "level_walking_warning",
    "pelvis_height_change_m",
    "plate_heights_m",
]

#: Span over which each pelvis marker's height is averaged (s): about one stride.
HEIGHT_AVERAGE_S: float = 1.0
#: A pelvis rising or falling more than this over the trial (m) does not walk on the level: half a stair riser.
MAX_PELVIS_CHANGE_M: float = 0.075
#: Force plates whose heights differ by more than this (m) do not lie in one level floor.
MAX_PLATE_HEIGHT_RANGE_M: float = 0.01


def pelvis_height_change_m(markers_m, names: Sequence[str], rate_hz: float, up) -> float:
    """The pelvis's largest rise (positive) or fall (negative) over a trial (m; module docstring).

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m, lab frame, NaN where missing.
    names : sequence of str
        The markers' model names (after the label map).
    rate_hz : float
        Frame rate (Hz).
    up : array_like
        Shape (3,): the lab's up direction.

    Returns
    -------
    float
        NaN without pelvis markers present in at least two frames.
    """
    X = np.asarray(markers_m, dtype=float)
    u = np.asarray(up, dtype=float) / np.linalg.norm(up)
    pelvis = landmark_indices(names, ["asis"]) + landmark_indices(names, ["psis", "sacrum"])
    changes = []
    for k in pelvis:
        h = X[:, k] @ u
        h = h[np.isfinite(h)]
        if h.size < 2:
            continue
        n = max(1, min(round(HEIGHT_AVERAGE_S * float(rate_hz)), h.size // 2))
        mean = np.convolve(h, np.ones(n) / n, mode="valid")
        high, low = int(np.argmax(mean)), int(np.argmin(mean))
        change = float(mean[high] - mean[low])
        changes.append(change if high >= low else -change)
    return float(np.median(changes)) if changes else float("nan")


def plate_heights_m(corners_m: Sequence, up) -> np.ndarray:
    """Each force plate's height along the lab's ``up`` (m): the mean of its corners ((4, 3) each, m, lab
    frame)."""
    u = np.asarray(up, dtype=float) / np.linalg.norm(up)
    return np.array([float(np.mean(np.asarray(c, dtype=float) @ u)) for c in corners_m])


def level_walking_warning(pelvis_change_m: float, plate_heights: Sequence[float]) -> str:
    """The warning of a trial that is not level walking, naming its figures; '' for a level walk.

    Parameters
    ----------
    pelvis_change_m : float
        :func:`pelvis_height_change_m` (NaN: not checked).
    plate_heights : sequence of float
        :func:`plate_heights_m`, m (empty: no plates).
    """
    said = []
    if np.isfinite(pelvis_change_m) and abs(pelvis_change_m) > MAX_PELVIS_CHANGE_M:
        verb = "rises" if pelvis_change_m > 0 else "falls"
        said.append(
            f"the pelvis {verb} {abs(pelvis_change_m):.3f} m over the trial (more than {MAX_PELVIS_CHANGE_M} m, half "
            "a stair step)"
        )
    heights = np.asarray(plate_heights, dtype=float)
    spread = float(np.ptp(heights)) if heights.size else 0.0
    if spread > MAX_PLATE_HEIGHT_RANGE_M:
        listed = ", ".join(f"{h:.3f}" for h in heights)
        said.append(
            f"the force plates lie at different heights ({listed} m; {spread:.3f} m apart, more than "
            f"{MAX_PLATE_HEIGHT_RANGE_M} m)"
        )
    return f"not level walking: {'; '.join(said)}" if said else ""
