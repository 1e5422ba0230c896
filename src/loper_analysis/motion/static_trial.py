"""The static trial as scaling uses it: the window averaged, each marker's pose, the subject's mass and height.

A lab's static trial is rarely complete: markers are hidden for the first
frames (knee condyles while the subject settles, a forefoot marker behind the
other foot) or drop out for a few frames. OpenSim's ScaleTool averages the
static pose over a time range (the setup's ``time_range``), but it cannot
take a missing marker (NaN) in a TRC. Here:

* :func:`scale_window_s` - the frames averaged: the setup's time range when
  it sets one, else the stillest ``duration_s`` of the trial
  (:func:`stillest_window_s`; the first ``duration_s`` without markers),
  else all of it;
* :func:`stillest_window_s` - of all windows of ``duration_s``, the one
  where every marker stays within the motion limit and the measurement
  markers move least (ties: the earliest); a trial in which no window stays
  within the limit stops, naming the stillest window and its motion;
* :func:`static_pose` - within the window, each marker's missing frames take
  the marker's mean over the frames where it is present (so OpenSim's
  average of the window is the average over the present frames); a
  measurement marker absent from the whole window stops, naming the lab
  label, the model marker, the file and the window; another marker absent
  throughout is left out (it cannot place anything); a marker that moves
  more than a limit (RMS about its mean over the window) stops: the subject
  did not stand still, and the averaged pose would place markers wrongly;
* :func:`standing_mass_kg` - body mass from the force plates the subject
  stands on: mean total vertical force over the window divided by gravity;
* :func:`markers_off_plates` - the foot markers (those near the floor) not over a loaded plate: a subject with
  a foot beside the plates weighs less on them than their mass;
* :func:`model_height_m` - stature estimated from a scaled model: the hip
  joint centre's height above the lowest marker in the default pose, over
  Winter's ratio of that height to stature (0.530).

Times in s on the file's clock, markers (n_frames, n_markers, 3) in m (NaN
where missing), forces in N.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import where
from loper_analysis.constants import GRAVITY_M_PER_S2
from loper_analysis.errors import LoperInputError
from loper_analysis.swing_leg.anthropometry import ANKLE_HEIGHT_FRACTION, WINTER_SEGMENTS

__all__ = [
    "HIP_HEIGHT_FRACTION",
    "MASS_RANGE_KG",
    "StaticPose",
    "time_range_is_set",
    "scale_window_s",
    "StillWindow",
    "stillest_window_s",
    "static_pose",
    "log_static_pose",
    "standing_mass_kg",
    "markers_off_plates",
    "model_height_m",
    "FOOT_MARKER_HEIGHT_M",
    "PLATE_EDGE_MARGIN_M",
]

log = logging.getLogger(__name__)

#: Hip joint centre height over stature (Winter's table: thigh + shank + ankle height).
HIP_HEIGHT_FRACTION: float = WINTER_SEGMENTS["thigh"].length + WINTER_SEGMENTS["shank"].length + ANKLE_HEIGHT_FRACTION
#: Body masses a standing subject may have (kg): outside, the plates or their units are wrong.
MASS_RANGE_KG: tuple[float, float] = (20.0, 300.0)
#: Markers lower than this over the plates' surface (m) are taken for foot markers (heel, toe, malleoli).
FOOT_MARKER_HEIGHT_M: float = 0.15
#: A foot marker this far (m) beyond a plate's edge still counts as over the plate (a heel marker sits behind
#: the heel).
PLATE_EDGE_MARGIN_M: float = 0.03
#: Relative SD of the total vertical force above which a "standing" subject is not standing still.
_MAX_FORCE_CV = 0.1
#: Windows whose motion differs by less than this (m) count as equally still: the earliest is taken.
STILLNESS_TIE_M: float = 1e-6


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
        one (:func:`stillest_window_s`) when ``markers_m`` is given, else the
        first; None, or a trial shorter than that: the whole trial.
    source, setting : str
        The file and the setting, for messages.
    markers_m : array_like, optional
        Shape (n_frames, n_markers, 3), m, NaN where missing: the markers
        whose stillness chooses the window.
    labels, needed, max_motion_rms_m, lab_labels
        As in :func:`stillest_window_s`.

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
        (:func:`stillest_window_s`).
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
                "use markers.static_duration_s"
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
    its present frames from their mean, as :func:`static_pose` measures it;
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
        Length of the window, s (``markers.static_duration_s``).
    needed : sequence of str
        The markers the scale factors are measured between (the measurements' marker pairs).
    max_motion_rms_m : float, optional
        Largest RMS motion (m) of a marker about its mean over the window
        (``markers.static_max_motion_rms_m``); None: not checked.
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
    window_motion = {labels[j]: _motion_rms_m(W[present[:, j], j]) for j in range(len(labels)) if present[:, j].any()}
    still = StillWindow((float(t[sel][0]), float(t[sel][-1])), window_motion, [labels[j] for j in scored], len(motion))
    _log_still_window(still, source, duration_s, (float(t[0]), float(t[min(n, t.size) - 1])), motion[0], labels)
    if max_motion_rms_m is not None and complete.any():
        message = _moving_message(window_motion, still.window_s, float(max_motion_rms_m), lab_labels, source)
        if message:
            hint = f"a time range where the subject stands still ({setting}), " if "time_range" in setting else ""
            raise LoperInputError(
                f"{message}; it is the stillest {float(duration_s):g} s (markers.static_duration_s) of the static "
                f"trial ({t[0]:.4f} .. {t[-1]:.4f} s, {still.n_windows} windows compared): set {hint}a shorter "
                "markers.static_duration_s or a larger markers.static_max_motion_rms_m"
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


def _named(marker: str, lab_labels: Mapping[str, str] | None) -> str:
    """A model marker with the lab label that provides it: ``'RKNE' (model marker R.Knee)``."""
    label = (lab_labels or {}).get(marker)
    return f"'{label}' (model marker {marker})" if label and label != marker else f"'{marker}'"


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
        (``markers.static_max_motion_rms_m``); None: not checked.

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
        names = ", ".join(_named(m, lab_labels) for m in stop)
        raise LoperInputError(
            f"{where(source)}marker(s) {names} missing in every frame of the scaling window {start:.4f} .. "
            f"{end:.4f} s ({int(sel.sum())} frames) of the static trial: choose a window where they are present "
            f"({setting}, or markers.static_duration_s)"
        )
    keep = [j for j in range(len(labels)) if present[:, j].any()]
    motion = {labels[j]: _motion_rms_m(W[present[:, j], j]) for j in keep}
    if max_motion_rms_m is not None:
        message = _moving_message(motion, (start, end), max_motion_rms_m, lab_labels, source)
        if message:
            raise LoperInputError(f"{message}; choose a still window ({setting}, or markers.static_duration_s)")
    filled = {}
    for j in keep:
        gap = ~present[:, j]
        if gap.any():
            W[gap, j] = W[present[:, j], j].mean(axis=0)
            filled[labels[j]] = int(gap.sum())
    return StaticPose(t[sel], W[:, keep], [labels[j] for j in keep], filled, absent, motion)


def _moving_message(
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
    shown = ", ".join(f"{_named(m, lab_labels)} {motion[m] * 1000:.0f} mm" for m in moving[:5])
    more = f" and {len(moving) - 5} more" if len(moving) > 5 else ""
    return (
        f"{where(source)}the subject does not stand still in the scaling window {window_s[0]:.4f} .. "
        f"{window_s[1]:.4f} s of the static trial: marker(s) {shown}{more} move more than "
        f"markers.static_max_motion_rms_m {max_motion_rms_m:g} m RMS about their mean"
    )


def _motion_rms_m(points_m: np.ndarray) -> float:
    """RMS distance (m) of points (n, 3) from their mean."""
    return float(np.sqrt(np.mean(np.sum((points_m - points_m.mean(axis=0)) ** 2, axis=1))))


def standing_mass_kg(
    time_s,
    vertical_force_n,
    window_s: tuple[float, float],
    gravity_m_per_s2: float = GRAVITY_M_PER_S2,
    source: str = "",
) -> float:
    """Body mass (kg) of a subject standing on force plates: mean total vertical force over the window / g.

    Parameters
    ----------
    time_s : array_like
        Shape (n_samples,), s: the plates' sample times.
    vertical_force_n : array_like
        Shape (n_samples,) or (n_samples, n_plates), N: vertical ground
        reaction of each plate (up positive), summed over the plates.
    window_s : (float, float)
        The span averaged (s).
    gravity_m_per_s2 : float
        Gravity (m/s^2).

    Raises
    ------
    LoperInputError
        No sample in the window, a mass outside :data:`MASS_RANGE_KG` (plates
        not under the subject, or in another unit), or a force that varies by
        more than 10 % (SD over mean: the subject does not stand still on the
        plates).
    """
    t = np.asarray(time_s, dtype=float)
    F = np.asarray(vertical_force_n, dtype=float)
    total = F.sum(axis=1) if F.ndim == 2 else F
    sel = (t >= window_s[0] - 1e-9) & (t <= window_s[1] + 1e-9) & np.isfinite(total)
    if not sel.any():
        raise LoperInputError(
            f"{where(source)}no force-plate sample in the window {window_s[0]:.4f} .. "
            f"{window_s[1]:.4f} s of the static trial"
        )
    mean = float(total[sel].mean())
    mass = mean / float(gravity_m_per_s2)
    lo, hi = MASS_RANGE_KG
    if not lo <= mass <= hi:
        raise LoperInputError(
            f"{where(source)}the force plates carry {mean:.1f} N on average in the static trial's window "
            f"({mass:.1f} kg), outside {lo:g} .. {hi:g} kg: does the subject stand on the plates? Give mass_kg in the "
            "subject sheet instead"
        )
    cv = float(total[sel].std()) / mean
    if cv > _MAX_FORCE_CV:
        raise LoperInputError(
            f"{where(source)}the total vertical force varies by {100 * cv:.0f} % (SD over mean) in the static trial's "
            f"window: the subject does not stand still on the plates; give mass_kg in the subject sheet instead"
        )
    return mass


def model_height_m(model, thigh_body: str) -> float:
    """Stature (m) of a scaled model: its hip joint centre's height over its lowest marker /
    :data:`HIP_HEIGHT_FRACTION`.

    ``model`` is an ``opensim.Model`` in its default pose; ``thigh_body``
    the thigh (femur) body, whose origin is the hip joint centre (gait2392,
    Rajagopal2016 and the generated model). The vertical is the model's Y.
    NaN for a model without markers.
    """
    state = model.initSystem()
    hip = model.getBodySet().get(thigh_body).getPositionInGround(state).to_numpy()
    markers = model.getMarkerSet()
    heights = [markers.get(i).getLocationInGround(state).to_numpy()[1] for i in range(markers.getSize())]
    if not heights:
        return float("nan")
    return float((hip[1] - min(heights)) / HIP_HEIGHT_FRACTION)


def markers_off_plates(
    markers_m,
    labels: Sequence[str],
    corners_m: Sequence,
    up,
    floor_m: float,
    max_height_m: float = FOOT_MARKER_HEIGHT_M,
    margin_m: float = PLATE_EDGE_MARGIN_M,
) -> tuple[list[str], list[str]]:
    """The foot markers of a standing pose and those of them that are over none of the given plates.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_markers, 3), m, lab frame: the pose (NaN: marker missing).
    labels : sequence of str
        The markers' names.
    corners_m : sequence of array_like
        Each loaded plate's four corners, shape (4, 3), m, lab frame, around its outline.
    up : array_like
        Shape (3,): the lab's up direction.
    floor_m : float
        Height of the plates' surface along ``up`` (m).
    max_height_m, margin_m : float
        Height over the plates' surface below which a marker is a foot marker (m); distance beyond a plate's
        edge still counted as over it (m).

    Returns
    -------
    (list of str, list of str)
        The foot markers; those over no plate (empty: the subject stands on the plates with both feet).
    """
    X = np.asarray(markers_m, float)
    u = np.asarray(up, float) / np.linalg.norm(up)
    plates = [np.asarray(c, float) for c in corners_m]
    e1 = np.cross(u, [1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.cross(u, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)

    def flat(p):
        return np.stack([p @ e1, p @ e2], axis=-1)

    feet, off = [], []
    for name, x in zip(labels, X, strict=True):
        if not np.all(np.isfinite(x)) or x @ u - floor_m > max_height_m:
            continue
        feet.append(name)
        if not any(_inside(flat(x), flat(c), margin_m) for c in plates):
            off.append(name)
    return feet, off


def _inside(point, polygon, margin: float) -> bool:
    """Whether a 2-D point lies inside a convex polygon (either winding) or within ``margin`` of its edges."""
    n = len(polygon)
    edges = [(polygon[i], polygon[(i + 1) % n]) for i in range(n)]
    sides = []
    for a, b in edges:
        d = b - a
        sides.append((d[0] * (point[1] - a[1]) - d[1] * (point[0] - a[0])) / np.linalg.norm(d))
    sides = np.asarray(sides)
    centre = polygon.mean(axis=0)
    inward = np.sign([(b - a)[0] * (centre[1] - a[1]) - (b - a)[1] * (centre[0] - a[0]) for a, b in edges])
    return bool(np.all(sides * inward >= -margin))


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
