"""How still the markers of a static trial stand: each marker's motion over a window, the markers beyond the
limit, and the stillest window of the trial.

* :func:`stillest_window_s` - of all windows of ``duration_s``, the one
  where every marker stays within the motion limit and the measurement
  markers move least (ties: the earliest); a trial in which no window stays
  within the limit stops, naming the stillest window and its motion;
* :func:`motion_rms_m` - a marker's motion over a window: the RMS distance of its present positions from their
  mean;
* :func:`moving_message` - the markers that move more than the limit over a window, named with their lab labels
  and motion (the stop of :func:`stillest_window_s` and of :func:`loper_analysis.motion.static_trial.static_pose`).

Times in s on the file's clock, markers (n_frames, n_markers, 3) in m (NaN where missing).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import where
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.marker_names import with_lab_label

__all__ = ["STILLNESS_TIE_M", "StillWindow", "stillest_window_s", "motion_rms_m", "moving_message"]

log = logging.getLogger(__name__)

#: Windows whose motion differs by less than this (m) count as equally still: the earliest is taken.
STILLNESS_TIE_M: float = 1e-6


@dataclass(frozen=True)
class StillWindow:
    """The stillest window of a static trial (:func:`stillest_window_s`).

    Attributes
    ----------
    window_s : (float, float)
        First and last frame time of the window, s.
    motion_rms_m : dict of str to float
        Marker -> RMS distance (m) of its present frames from its mean over the window (markers present in it).
    scored : list of str
        The markers whose largest motion chose the window among those within the limit (the measurement
        markers; all markers when none is given).
    n_windows : int
        Windows compared (one per start frame).
    """

    window_s: tuple[float, float]
    motion_rms_m: dict[str, float]
    scored: list[str]
    n_windows: int

    def largest(self, markers: Sequence[str] | None = None) -> tuple[str, float]:
        """The marker that moves most over the window, of ``markers`` (None: of all), and its motion (m)."""
        among = [m for m in (self.motion_rms_m if markers is None else markers) if m in self.motion_rms_m]
        if not among:
            return "", 0.0
        top = max(among, key=self.motion_rms_m.get)
        return top, self.motion_rms_m[top]


def stillest_window_s(
    time_s,
    markers_m,
    labels: Sequence[str],
    duration_s: float,
    *,
    needed: Sequence[str] = (),
    max_motion_rms_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
    source: str = "",
    setting: str = "time_range of the scale setup",
) -> StillWindow:
    """The window of ``duration_s`` where the subject stands stillest.

    The windows compared start at each frame and hold as many frames as the
    trial's first ``duration_s`` (a trial no longer than that is one window,
    the whole trial). A marker's motion over a window is the RMS distance of
    its present frames from their mean, as :func:`loper_analysis.motion.static_trial.static_pose` measures it;
    markers absent from a window do not count, and a window from which a
    ``needed`` marker is absent is not taken (unless every window lacks one:
    then the first, for :func:`static_pose` to name the marker). Among the
    windows where every marker's motion stays within ``max_motion_rms_m``,
    the one whose ``needed`` markers' largest motion is least (all markers'
    when ``needed`` is empty); when no window stays within the limit, the
    one whose largest motion of any marker is least, and the call stops.
    Windows within :data:`STILLNESS_TIE_M` of the least count as equal: the
    earliest is taken. The choice is logged.

    Parameters
    ----------
    time_s : array_like
        Shape (n_frames,), s: the static trial's frame times (evenly spaced).
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m, NaN where missing.
    labels : sequence of str
        Marker names, one per marker.
    duration_s : float
        Length of the window, s (``model.static_duration_s``).
    needed : sequence of str
        The markers the scale factors are measured between (the measurements' marker pairs).
    max_motion_rms_m : float, optional
        Largest RMS motion (m) of a marker about its mean over the window
        (``model.static_max_motion_rms_m``); None: not checked.
    lab_labels : mapping of str to str, optional
        Model marker -> the lab's label in the C3D file, for messages.
    source, setting : str
        The file and the setting that would set a time range, for messages.

    Returns
    -------
    StillWindow
        The window and its markers' motion.

    Raises
    ------
    LoperInputError
        Even the stillest window has a marker moving more than
        ``max_motion_rms_m``: the message names the file, the window, the
        markers beyond the limit with their motion (mm) and the settings to
        change.
    """
    t = np.asarray(time_s, dtype=float)
    X = np.asarray(markers_m, dtype=float)
    labels = [str(lab) for lab in labels]
    if t.ndim != 1 or t.size == 0:
        raise LoperInputError(f"{where(source)}the static trial holds no frame")
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] != t.size or X.shape[1] != len(labels):
        raise LoperInputError(f"{where(source)}markers_m must have shape ({t.size}, {len(labels)}, 3), got {X.shape}")
    n = max(int(np.count_nonzero(t < t[0] + float(duration_s) - 1e-9)), 1)
    motion = _sliding_motion_rms_m(X, n)  # (n_windows, n_markers), NaN where absent
    scored = [j for j, m in enumerate(labels) if m in set(needed)] or list(range(len(labels)))
    with np.errstate(invalid="ignore"):
        worst = np.where(np.isnan(motion), -np.inf, motion).max(axis=1)
        worst_scored = np.where(np.isnan(motion[:, scored]), -np.inf, motion[:, scored]).max(axis=1)
    worst_scored[np.isneginf(worst_scored)] = np.inf  # no marker to judge the window by
    limit = np.inf if max_motion_rms_m is None else float(max_motion_rms_m)
    excess = np.maximum(worst - limit, 0.0)
    complete = ~np.isnan(motion[:, [j for j in scored if labels[j] in set(needed)]]).any(axis=1)
    if complete.any():
        excess = np.where(complete, excess, np.inf)
        candidates = excess <= excess.min() + STILLNESS_TIE_M
        key = np.where(candidates, worst_scored, np.inf)
        first = int(np.flatnonzero(key <= key.min() + STILLNESS_TIE_M)[0])
    else:
        first = 0
    sel = slice(first, first + n)
    W = X[sel]
    present = np.all(np.isfinite(W), axis=2)
    window_motion = {labels[j]: motion_rms_m(W[present[:, j], j]) for j in range(len(labels)) if present[:, j].any()}
    still = StillWindow((float(t[sel][0]), float(t[sel][-1])), window_motion, [labels[j] for j in scored], len(motion))
    _log_still_window(still, source, duration_s, (float(t[0]), float(t[min(n, t.size) - 1])), motion[0], labels)
    if max_motion_rms_m is not None and complete.any():
        message = moving_message(window_motion, still.window_s, float(max_motion_rms_m), lab_labels, source)
        if message:
            hint = f"a time range where the subject stands still ({setting}), " if "time_range" in setting else ""
            raise LoperInputError(
                f"{message}; it is the stillest {float(duration_s):g} s (model.static_duration_s) of the static "
                f"trial ({t[0]:.4f} .. {t[-1]:.4f} s, {still.n_windows} windows compared): set {hint}a shorter "
                "model.static_duration_s or a larger model.static_max_motion_rms_m"
            )
    return still


def _sliding_motion_rms_m(X: np.ndarray, n: int) -> np.ndarray:
    """Each marker's RMS distance (m) from its mean over every window of ``n`` frames, over its present frames.

    ``X`` (n_frames, n_markers, 3), NaN where missing; returns (n_frames - n + 1, n_markers), NaN where the
    marker is absent from the whole window. Running sums of positions taken about each marker's mean over the
    trial (so that the variance is not lost in the squares of metres).
    """
    present = np.all(np.isfinite(X), axis=2)
    with np.errstate(invalid="ignore"):
        centre = np.nanmean(np.where(present[..., None], X, np.nan), axis=0)
    D = np.where(present[..., None], X - np.nan_to_num(centre), 0.0)

    def window_sums(a: np.ndarray) -> np.ndarray:
        c = np.concatenate([np.zeros((1, *a.shape[1:])), np.cumsum(a, axis=0)])
        return c[n:] - c[:-n]

    count = window_sums(present.astype(float))
    s1 = window_sums(D)
    s2 = window_sums(np.sum(D**2, axis=2))
    with np.errstate(invalid="ignore", divide="ignore"):
        var = s2 / count - np.sum(s1**2, axis=2) / count**2
    return np.where(count > 0, np.sqrt(np.maximum(var, 0.0)), np.nan)


def _log_still_window(
    still: StillWindow,
    source: str,
    duration_s: float,
    first_s: tuple[float, float],
    first_motion: np.ndarray,
    labels: Sequence[str],
) -> None:
    """The stillest window and its largest motion, with the first window's for comparison, in the log."""
    scored, scored_m = still.largest(still.scored)
    any_marker, any_m = still.largest()
    with np.errstate(invalid="ignore"):
        j = int(np.nanargmax(np.where(np.isnan(first_motion), -np.inf, first_motion)))
    kind = "all markers" if len(still.scored) == len(labels) else "measurement markers"
    log.info(
        "%s: stillest %g s of the static trial (of %d windows): %.4f .. %.4f s, largest motion (RMS about the mean) "
        "of the %s %s %.1f mm, of any marker %s %.1f mm; the first %g s (%.4f .. %.4f s): %s %.1f mm",
        source,
        duration_s,
        still.n_windows,
        *still.window_s,
        kind,
        scored,
        scored_m * 1000,
        any_marker,
        any_m * 1000,
        duration_s,
        *first_s,
        labels[j],
        first_motion[j] * 1000,
    )


def moving_message(
    motion: Mapping[str, float],
    window_s: tuple[float, float],
    max_motion_rms_m: float,
    lab_labels: Mapping[str, str] | None,
    source: str,
) -> str:
    """The markers of ``motion`` (m) beyond ``max_motion_rms_m`` over the window, most first: "" when none."""
    moving = sorted((m for m in motion if motion[m] > max_motion_rms_m), key=motion.get, reverse=True)
    if not moving:
        return ""
    shown = ", ".join(f"{with_lab_label(m, lab_labels)} {motion[m] * 1000:.0f} mm" for m in moving[:5])
    more = f" and {len(moving) - 5} more" if len(moving) > 5 else ""
    return (
        f"{where(source)}the subject does not stand still in the scaling window {window_s[0]:.4f} .. "
        f"{window_s[1]:.4f} s of the static trial: marker(s) {shown}{more} move more than "
        f"model.static_max_motion_rms_m {max_motion_rms_m:g} m RMS about their mean"
    )


def motion_rms_m(points_m: np.ndarray) -> float:
    """RMS distance (m) of points (n, 3) from their mean."""
    return float(np.sqrt(np.mean(np.sum((points_m - points_m.mean(axis=0)) ** 2, axis=1))))
