"""The static trial as scaling uses it: the window averaged and each marker's pose over it.

A lab's static trial is rarely complete: markers are hidden for the first
frames (knee condyles while the subject settles, a forefoot marker behind the
other foot) or drop out for a few frames. OpenSim's ScaleTool averages the
static pose over a time range (the setup's ``time_range``), but it cannot
take a missing marker (NaN) in a TRC. Here:

* :func:`scale_window_s` - the frames averaged: the setup's time range when
  it sets one, else the stillest ``duration_s`` of the trial
  (:func:`loper_analysis.motion.still_window.stillest_window_s`; the first ``duration_s`` without markers),
  else all of it;
* :func:`static_pose` - within the window, each marker's missing frames take
  the marker's mean over the frames where it is present (so OpenSim's
  average of the window is the average over the present frames); a
  measurement marker absent from the whole window stops, naming the lab
  label, the model marker, the file and the window; another marker absent
  throughout is left out (it cannot place anything); a marker that moves
  more than a limit (RMS about its mean over the window) stops: the subject
  did not stand still, and the averaged pose would place markers wrongly;
* :func:`log_static_pose` - the pose's largest motion, the markers filled and those left out, in the log.

The subject's mass and height from the static trial are :mod:`loper_analysis.motion.body_size`'s.

Times in s on the file's clock, markers (n_frames, n_markers, 3) in m (NaN
where missing).
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import where
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.marker_names import with_lab_label
from loper_analysis.motion.still_window import motion_rms_m, moving_message, stillest_window_s

__all__ = [
    "StaticPose",
    "time_range_is_set",
    "scale_window_s",
    "static_pose",
    "log_static_pose",
]

log = logging.getLogger(__name__)


def time_range_is_set(time_range) -> bool:
    """Whether a ScaleTool time range is set: two finite times, start <= end, not OpenSim's unset ``-1 -1``."""
    if time_range is None:
        return False
    a, b = (float(v) for v in time_range)
    return bool(np.isfinite(a) and np.isfinite(b) and a <= b and not (a < 0 and b < 0))


def scale_window_s(
    time_s,
    setup_ranges_s: Sequence[Sequence[float] | None] = (),
    duration_s: float | None = None,
    source: str = "",
    setting: str = "time_range of the scale setup",
    *,
    markers_m=None,
    labels: Sequence[str] = (),
    needed: Sequence[str] = (),
    max_motion_rms_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> tuple[float, float]:
    """The span of the static trial that scaling averages (s, the file's clock).

    Parameters
    ----------
    time_s : array_like
        Shape (n_frames,), s: the static trial's frame times.
    setup_ranges_s : sequence of (start, end) or None
        The time ranges a ScaleTool setup sets (model scaler, marker placer);
        unset ones (None, ``-1 -1`` or start > end) are ignored. The window
        spans those that are set (only checked to hold frames: a range set
        is the lab's choice).
    duration_s : float, optional
        Without a set range: a window of ``duration_s`` seconds, the stillest
        one (:func:`loper_analysis.motion.still_window.stillest_window_s`) when ``markers_m`` is given, else the
        first; None, or a trial shorter than that: the whole trial.
    source, setting : str
        The file and the setting, for messages.
    markers_m : array_like, optional
        Shape (n_frames, n_markers, 3), m, NaN where missing: the markers
        whose stillness chooses the window.
    labels, needed, max_motion_rms_m, lab_labels
        As in :func:`loper_analysis.motion.still_window.stillest_window_s`.

    Returns
    -------
    (float, float)
        First and last time of the window (both frame times of the trial).

    Raises
    ------
    LoperInputError
        A set range that holds no frame of the trial (naming the range, the
        trial's span, the file and ``setting``); a trial in which even the
        stillest window moves more than ``max_motion_rms_m``
        (:func:`loper_analysis.motion.still_window.stillest_window_s`).
    """
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size == 0:
        raise LoperInputError(f"{where(source)}the static trial holds no frame")
    ranges = [tuple(float(v) for v in r) for r in setup_ranges_s if time_range_is_set(r)]
    if ranges:
        start, end = min(r[0] for r in ranges), max(r[1] for r in ranges)
        inside = t[(t >= start - 1e-9) & (t <= end + 1e-9)]
        if not inside.size:
            raise LoperInputError(
                f"{where(source)}{setting} {start:g} .. {end:g} s holds no frame of the static trial "
                f"({t[0]:.4f} .. {t[-1]:.4f} s, the file's clock): set it to a span of the trial, or to -1 -1 to "
                "use model.static_duration_s"
            )
        return float(inside[0]), float(inside[-1])
    if duration_s is None:
        return float(t[0]), float(t[-1])
    inside = t[t < t[0] + float(duration_s) - 1e-9]
    if markers_m is not None and inside.size < t.size:
        still = stillest_window_s(
            t,
            markers_m,
            labels,
            duration_s,
            needed=needed,
            max_motion_rms_m=max_motion_rms_m,
            lab_labels=lab_labels,
            source=source,
            setting=setting,
        )
        return still.window_s
    return float(inside[0]), float(inside[-1])


@dataclass(frozen=True)
class StaticPose:
    """The static trial's window as ScaleTool gets it (:func:`static_pose`).

    Attributes
    ----------
    time_s : numpy.ndarray
        Shape (n,), s: the window's frames.
    markers_m : numpy.ndarray
        Shape (n, n_kept, 3), m: no NaN; a marker's missing frames hold its mean over its present frames.
    labels : list of str
        The model names of the kept markers.
    n_filled : dict of str to int
        Marker -> frames of the window filled with its mean (only markers with some).
    left_out : list of str
        Markers absent from the whole window (not measurement markers), left out.
    motion_rms_m : dict of str to float
        Kept marker -> RMS distance (m) of its present frames from its mean over the window.
    """

    time_s: np.ndarray
    markers_m: np.ndarray
    labels: list[str]
    n_filled: dict[str, int]
    left_out: list[str]
    motion_rms_m: dict[str, float]


def static_pose(
    time_s,
    markers_m,
    labels: Sequence[str],
    *,
    window_s: tuple[float, float],
    needed: Sequence[str] = (),
    lab_labels: Mapping[str, str] | None = None,
    source: str = "",
    setting: str = "time_range of the scale setup",
    max_motion_rms_m: float | None = None,
) -> StaticPose:
    """The frames of ``window_s`` with every marker complete (module docstring).

    Parameters
    ----------
    time_s : array_like
        Shape (n_frames,), s.
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m, NaN where missing.
    labels : sequence of str
        Model marker names, one per marker.
    window_s : (float, float)
        The span averaged (:func:`scale_window_s`).
    needed : sequence of str
        Markers scaling cannot do without (the measurements' marker pairs).
    lab_labels : mapping of str to str, optional
        Model marker -> the lab's label in the C3D file, for messages.
    source, setting : str
        The file and the setting that chose the window, for messages.
    max_motion_rms_m : float, optional
        Largest RMS motion (m) of a marker about its mean over the window
        (``model.static_max_motion_rms_m``); None: not checked.

    Raises
    ------
    LoperInputError
        A marker of ``needed`` absent from the data, or from every frame of
        the window; the message names the lab label, the model marker, the
        file, the window and ``setting``. A marker moving more than
        ``max_motion_rms_m``: the message names the markers, their motion,
        the window and the limit.
    """
    t = np.asarray(time_s, dtype=float)
    X = np.asarray(markers_m, dtype=float)
    labels = [str(lab) for lab in labels]
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] != t.size or X.shape[1] != len(labels):
        raise LoperInputError(f"{where(source)}markers_m must have shape ({t.size}, {len(labels)}, 3), got {X.shape}")
    lacking = [m for m in needed if m not in labels]
    if lacking:
        raise LoperInputError(
            f"{where(source)}static trial lacks marker(s) {sorted(set(lacking))} needed for scaling "
            "(map the lab's labels to them in markers.label_map)"
        )
    start, end = window_s
    sel = (t >= start - 1e-9) & (t <= end + 1e-9)
    W = X[sel].copy()
    present = np.all(np.isfinite(W), axis=2)
    absent = [labels[j] for j in range(len(labels)) if not present[:, j].any()]
    stop = [m for m in absent if m in set(needed)]
    if stop:
        names = ", ".join(with_lab_label(m, lab_labels) for m in stop)
        raise LoperInputError(
            f"{where(source)}marker(s) {names} missing in every frame of the scaling window {start:.4f} .. "
            f"{end:.4f} s ({int(sel.sum())} frames) of the static trial: choose a window where they are present "
            f"({setting}, or model.static_duration_s)"
        )
    keep = [j for j in range(len(labels)) if present[:, j].any()]
    motion = {labels[j]: motion_rms_m(W[present[:, j], j]) for j in keep}
    if max_motion_rms_m is not None:
        message = moving_message(motion, (start, end), max_motion_rms_m, lab_labels, source)
        if message:
            raise LoperInputError(f"{message}; choose a still window ({setting}, or model.static_duration_s)")
    filled = {}
    for j in keep:
        gap = ~present[:, j]
        if gap.any():
            W[gap, j] = W[present[:, j], j].mean(axis=0)
            filled[labels[j]] = int(gap.sum())
    return StaticPose(t[sel], W[:, keep], [labels[j] for j in keep], filled, absent, motion)


def log_static_pose(pose: StaticPose, static_trc: str, window: tuple[float, float]) -> None:
    """The static pose's largest marker motion, the markers filled and those left out, in the log."""
    moving = sorted(pose.motion_rms_m, key=pose.motion_rms_m.get, reverse=True)[:3]
    log.info(
        "%s: largest marker motion over the window (RMS about the mean): %s",
        static_trc,
        ", ".join(f"{m} {pose.motion_rms_m[m] * 1000:.1f} mm" for m in moving),
    )
    for marker, n in pose.n_filled.items():
        log.info(
            "%s: marker %s missing in %d of %d frames of the window: averaged over the others",
            static_trc,
            marker,
            n,
            len(pose.time_s),
        )
    if pose.left_out:
        log.warning(
            "%s: marker(s) %s missing throughout the window %.4f .. %.4f s: left out of scaling",
            static_trc,
            ", ".join(pose.left_out),
            *window,
        )
