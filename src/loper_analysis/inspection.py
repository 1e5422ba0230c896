"""What a lab's C3D file holds: markers, force platforms, channels, events, lab axes and label matching.

The library side of ``loper-analysis inspect`` (the file side is
:mod:`loper_analysis.steps.inspect`). Every function takes arrays or
records already read (:class:`~loper_analysis.io.c3d.C3DRecording`,
:class:`~loper_analysis.io.force_platforms.ForcePlatform`) and returns new
objects; :func:`format_summary` and :func:`format_label_match` turn them
into plain text.

Marker presence (:func:`marker_presence`)
    A marker is present in a frame when its three coordinates are finite
    (the reader's missing points are NaN). The longest gap is the longest
    run of missing frames between the marker's first and last present
    frame; frames before the first and after the last present frame are
    described by those two frame numbers instead. Frame numbers are the
    file's own (0-based, ``first_frame + k`` for row ``k``).

Force platforms (:func:`plate_summary`)
    The normal is the right-hand normal of the corners in file order
    (``(c3 - c1) x (c4 - c2)``, unit length): it points down for corners
    listed clockwise seen from above, the order the C3D format gives (its
    plate z axis points down), and up for corners listed counter-clockwise.
    Either order is reported, neither is refused. The resting level is
    :func:`loper_analysis.ground_reaction.resting_level` of the force along
    the lab's upward axis; a plate loaded throughout has none.

Lab axes (:func:`vertical_axis`, :func:`walking_direction`)
    The vertical axis comes from the force platforms when they tell it: the
    lab axis along the plates' normals, pointing the way the largest force
    points (the force on the body points up while someone stands on a
    plate). Otherwise, and as a check, from the markers: the axis along
    which the markers of a frame spread most (feet to pelvis or head; the
    median over frames with at least 3 markers), pointing the way most
    coordinates lie (markers are above the floor). The walking direction is
    the horizontal axis of the largest travel (median over markers of the
    last minus the first present position) and its sign; less than
    ``min_travel_m`` on both horizontal axes is read as treadmill walking
    or standing.

Rotation into the model frame (:func:`lab_to_model_rotation_deg`)
    Three angles (degrees) about the fixed X, Y, Z axes as
    :func:`loper_analysis.markers.rotate_markers` applies them. The
    suggestion is the smallest turn taking the lab's upward axis to
    OpenSim's +Y: Z-up lab -> ``(-90, 0, 0)``, Y-up lab -> ``(0, 0, 0)``.
    Given a walking direction as well, the rotation that also takes it to
    model +X (OpenSim's forward): among the triples of multiples of 90
    degrees doing that, the one with the fewest and smallest turns (Z-up
    lab walking -X -> ``(-90, 180, 0)``).

Label matching (:func:`match_labels`)
    Lab labels (subject prefix stripped,
    :func:`loper_analysis.marker_names.strip_subject_prefix`) are matched
    to model markers in four rounds, each on the labels and markers still
    free: the same name; the same name ignoring case; the same name
    ignoring case and every character but letters and digits (``R.ASIS``,
    ``R_ASIS``, ``RASIS``); the same side (a leading ``L``/``R``,
    ``Left``/``Right``, or a trailing ``_l``/``_r``) and landmark in
    :data:`LANDMARK_SYNONYMS`. A label with more than one candidate marker,
    or two labels wanting one marker, is ambiguous and stays unmatched.
"""

from __future__ import annotations

import itertools
import json
import re
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from .errors import LoperInputError
from .marker_names import strip_subject_prefix

if TYPE_CHECKING:  # records only; nothing is read here
    from .io.c3d import C3DRecording
    from .io.force_platforms import ForcePlatform

__all__ = [
    "AXIS_NAMES",
    "LANDMARK_SYNONYMS",
    "MIN_MARKERS_PER_FRAME",
    "LabelMatch",
    "PlateSummary",
    "RecordingSummary",
    "VerticalAxis",
    "WalkingDirection",
    "axis_name",
    "config_snippet",
    "format_label_match",
    "format_summary",
    "heel_markers",
    "lab_to_model_rotation_deg",
    "marker_presence",
    "match_labels",
    "plate_summary",
    "recording_summary",
    "sparse_frames",
    "starter_label_map",
    "vertical_axis",
    "walking_direction",
]

#: Names of the lab axes 0, 1, 2.
AXIS_NAMES: tuple[str, str, str] = ("X", "Y", "Z")
#: Fewest markers in a frame for inverse kinematics to place the model.
MIN_MARKERS_PER_FRAME = 3

#: Landmark -> spellings (lowercase letters and digits, side removed) in Vicon Plug-in Gait, Qualisys/CAST
#: (ISB abbreviations), OpenSim's gait2392 and Rajagopal2016 marker sets. A label and a model marker match
#: through this table when they share side and landmark.
LANDMARK_SYNONYMS: dict[str, tuple[str, ...]] = {
    "asis": ("asi", "asis", "ias"),                                     # LASI, L.ASIS, L_IAS
    "psis": ("psi", "psis", "ips"),                                     # LPSI, L.PSIS, L_IPS
    "sacrum": ("sacr", "sacrum", "sacral", "vsacral"),                  # SACR, V.Sacral
    "heel": ("hee", "heel", "cal", "fcc"),                              # LHEE, L.Heel, LCAL, L_FCC
    "toe": ("toe", "toetip", "ft2"),                                    # LTOE, L.Toe, L.Toe.Tip, L_FT2
    "mt1": ("mt1", "met1", "fm1", "toemed"),                            # LMT1, L_FM1, L.Toe.Med
    "mt5": ("mt5", "met5", "fm5", "toelat"),                            # LMT5, L_FM5, L.Toe.Lat
    "knee_lateral": ("kne", "knee", "kneelat", "lknee", "lfc", "fle"),  # LKNE, L.Knee(.Lat), LLFC, L_FLE
    "knee_medial": ("kneemed", "mknee", "mfc", "fme"),                  # L.Knee.Med, L.MKnee, LMFC, L_FME
    "ankle_lateral": ("ank", "ankle", "anklelat", "lankle", "lmal", "fal"),  # LANK, L.Ankle(.Lat), LLMAL, L_FAL
    "ankle_medial": ("anklemed", "mankle", "mmal", "tam"),              # L.Ankle.Med, L.MAnkle, LMMAL, L_TAM
    "acromion": ("sho", "shoulder", "acr", "acromion", "acromium", "sae"),  # LSHO, LACR, L.Acromium, L_SAE
    "sternum": ("strn", "sternum", "sjn"),                              # STRN, Sternum, SJN
    "head_top": ("tophead", "headtop", "vertex"),                       # Top.Head, HEAD_TOP
}

_SPELLING_TO_LANDMARK = {s: name for name, spellings in LANDMARK_SYNONYMS.items() for s in spellings}
_NOT_ALNUM = re.compile(r"[^0-9a-z]")
_SIDE_SUFFIX = re.compile(r"[._\-\s]([lr])$", re.IGNORECASE)
#: Rounds of :func:`match_labels`, in order.
_RULES = ("exact", "case", "punctuation", "synonym")


# ---------------------------------------------------------------- records


@dataclass(frozen=True)
class PlateSummary:
    """One force platform as :func:`plate_summary` describes it (lab frame, SI units).

    Attributes
    ----------
    number, type : int
        Plate number (1-based) and ``FORCE_PLATFORM:TYPE``.
    channels : tuple of int
        1-based analog channels the plate uses.
    corners_m : numpy.ndarray
        Shape (4, 3), m, in file order.
    centre_m : numpy.ndarray
        Shape (3,), m: mean of the corners.
    side_lengths_m : tuple of float
        Lengths of the sides corner 1-2 and corner 1-4 (m).
    normal : numpy.ndarray
        Shape (3,): right-hand unit normal of the corners in file order.
    corner_order : str
        ``"clockwise"`` or ``"counter-clockwise"`` seen from above (the
        lab's upward axis), ``""`` when the normal is not within 45 degrees
        of the vertical.
    rest_vertical_n : float or None
        Resting (unloaded) upward force (N); None when the plate is loaded throughout.
    peak_vertical_n : float
        Largest upward force above the resting level (N; as read when there is no resting level).
    peak_time_s : float
        Time of that peak (s, the file's clock).
    loaded_pct : float
        Share of samples more than ``threshold_n`` above the resting level (%).
    """

    number: int
    type: int
    channels: tuple[int, ...]
    corners_m: np.ndarray
    centre_m: np.ndarray
    side_lengths_m: tuple[float, float]
    normal: np.ndarray
    corner_order: str
    rest_vertical_n: float | None
    peak_vertical_n: float
    peak_time_s: float
    loaded_pct: float


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


@dataclass(frozen=True)
class RecordingSummary:
    """Everything :func:`format_summary` prints about one C3D file.

    Attributes
    ----------
    source : str
        The file.
    point_unit : str
        ``POINT:UNITS`` as declared (markers are in m here regardless).
    point_rate_hz, analog_rate_hz : float
        Rates (Hz).
    first_frame, n_frames : int
        0-based first frame and number of frames.
    markers : pandas.DataFrame
        :func:`marker_presence`.
    sparse_frames : numpy.ndarray
        File frame numbers with fewer than 3 markers.
    n_empty_frames : int
        Frames without any marker.
    plates : list of PlateSummary
    plate_problem : str
        Why the plates could not be read ("" when they could or there are none).
    n_plates_declared : int
        ``FORCE_PLATFORM:USED``.
    analog_labels, analog_units : list of str
    events : pandas.DataFrame
        Columns ``context``, ``label``, ``time_s``.
    vertical : VerticalAxis
    walking : WalkingDirection
    rotation_deg : tuple of float
        Suggested ``markers.lab_to_model_rotation_deg``: the smallest rotation taking up to model +Y.
    rotation_forward_deg : tuple of float
        The rotation taking up to +Y and this trial's walking direction to +X (``rotation_deg`` when
        the markers do not travel).
    channel_owner : dict of int to str
        0-based analog channel -> ``"plate N Fx"`` etc.
    """

    source: str
    point_unit: str
    point_rate_hz: float
    analog_rate_hz: float
    first_frame: int
    n_frames: int
    markers: pd.DataFrame
    sparse_frames: np.ndarray
    n_empty_frames: int
    plates: list[PlateSummary]
    plate_problem: str
    n_plates_declared: int
    analog_labels: list[str]
    analog_units: list[str]
    events: pd.DataFrame
    vertical: VerticalAxis
    walking: WalkingDirection
    rotation_deg: tuple[float, float, float]
    rotation_forward_deg: tuple[float, float, float]
    channel_owner: dict[int, str] = field(default_factory=dict)

    @property
    def duration_s(self) -> float:
        """``n_frames / point_rate_hz`` (s)."""
        return self.n_frames / self.point_rate_hz

    @property
    def first_time_s(self) -> float:
        """Time of the first frame, ``first_frame / point_rate_hz`` (s)."""
        return self.first_frame / self.point_rate_hz


@dataclass(frozen=True)
class LabelMatch:
    """Lab labels matched to model markers (:func:`match_labels`).

    Attributes
    ----------
    pairs : tuple of (label, marker, rule)
        The file's label (as in the file), the model marker, and the round
        that matched them (``exact``, ``case``, ``punctuation``, ``synonym``), in file order.
    unmatched_labels : tuple of str
        Labels (as in the file) without a marker, ambiguous ones included.
    ambiguous : dict of str to tuple of str
        Label -> the markers it could have been (or the one marker two labels wanted).
    unprovided_markers : tuple of str
        Model markers no label provides, in model order.
    """

    pairs: tuple[tuple[str, str, str], ...]
    unmatched_labels: tuple[str, ...]
    ambiguous: dict[str, tuple[str, ...]]
    unprovided_markers: tuple[str, ...]


# ---------------------------------------------------------------- markers


def _markers_array(markers_m, source: str = "") -> np.ndarray:
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(f"{source or 'markers'}: markers_m must have shape (n_frames, n_markers, 3), "
                              f"got {X.shape}")
    return X


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of every run of True in a 1-D boolean array (stop exclusive)."""
    m = np.concatenate([[False], np.asarray(mask, dtype=bool), [False]])
    edges = np.flatnonzero(np.diff(m.astype(np.int8)))
    return [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2])]


def marker_presence(labels: Sequence[str], markers_m, point_rate_hz: float, first_frame: int = 0) -> pd.DataFrame:
    """Per marker: share of frames present, first and last present frame, longest gap.

    Parameters
    ----------
    labels : sequence of str
        One label per marker.
    markers_m : array_like
        Shape (n_frames, n_markers, 3), m; a point is present when all three coordinates are finite.
    point_rate_hz : float
        Frame rate (Hz), for the gaps in seconds.
    first_frame : int
        The file's 0-based number of row 0 (frame numbers below are the file's).

    Returns
    -------
    pandas.DataFrame
        One row per marker: ``label``, ``n_present``, ``present_pct`` (%),
        ``first_present_frame``, ``last_present_frame`` (nullable integers,
        missing for a marker never present), ``longest_gap_frames`` (longest
        run of missing frames between those two; 0 without a gap) and
        ``longest_gap_s`` (s).

    Raises
    ------
    LoperInputError
        Bad shape, a label count unlike the markers', or a rate that is not positive.
    """
    X = _markers_array(markers_m)
    if len(labels) != X.shape[1]:
        raise LoperInputError(f"markers: {len(labels)} label(s) for {X.shape[1]} marker(s)")
    if not float(point_rate_hz) > 0:
        raise LoperInputError(f"markers: point_rate_hz must be positive, got {point_rate_hz!r}")
    present = np.all(np.isfinite(X), axis=2)
    n_frames = X.shape[0]
    rows = []
    for j, label in enumerate(labels):
        idx = np.flatnonzero(present[:, j])
        if idx.size == 0:
            first = last = pd.NA
            gap = 0
        else:
            first, last = int(idx[0]) + first_frame, int(idx[-1]) + first_frame
            inner = ~present[idx[0]:idx[-1] + 1, j]
            gap = max((b - a for a, b in _runs(inner)), default=0)
        rows.append({"label": str(label), "n_present": int(idx.size),
                     "present_pct": 100.0 * idx.size / n_frames if n_frames else 0.0,
                     "first_present_frame": first, "last_present_frame": last,
                     "longest_gap_frames": int(gap), "longest_gap_s": gap / float(point_rate_hz)})
    table = pd.DataFrame(rows, columns=["label", "n_present", "present_pct", "first_present_frame",
                                        "last_present_frame", "longest_gap_frames", "longest_gap_s"])
    for col in ("first_present_frame", "last_present_frame"):
        table[col] = table[col].astype("Int64")
    return table


def sparse_frames(markers_m, first_frame: int = 0, min_markers: int = MIN_MARKERS_PER_FRAME) -> np.ndarray:
    """File frame numbers (``first_frame + k``) of the frames with fewer than ``min_markers`` present markers.

    Raises
    ------
    LoperInputError
        ``markers_m`` not of shape (n_frames, n_markers, 3).
    """
    X = _markers_array(markers_m)
    count = np.all(np.isfinite(X), axis=2).sum(axis=1)
    return np.flatnonzero(count < min_markers) + int(first_frame)


# ---------------------------------------------------------------- lab axes


def axis_name(axis: int | None, sign: int = 1) -> str:
    """``"+Z"``, ``"-X"`` ...; ``"none"`` for axis None."""
    return "none" if axis is None else ("+" if sign >= 0 else "-") + AXIS_NAMES[axis]


def _corner_normal(corners_m: np.ndarray) -> np.ndarray:
    """Right-hand unit normal of four corners in their order (NaN vector when degenerate)."""
    n = np.cross(corners_m[2] - corners_m[0], corners_m[3] - corners_m[1])
    norm = float(np.linalg.norm(n))
    return n / norm if norm > 0 else np.full(3, np.nan)


def _plate_vertical(plate: ForcePlatform, min_load_n: float) -> tuple[int | None, int | None]:
    """(axis, sign) of one plate: axis along its normal, sign of its largest force along it (None: cannot tell)."""
    n = _corner_normal(np.asarray(plate.corners_m, dtype=float))
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
    frames = present.sum(axis=1) >= MIN_MARKERS_PER_FRAME
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
    X = _markers_array(markers_m)
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
    X = _markers_array(markers_m)
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


def _rotation_matrix(angles_deg: Sequence[float]) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("xyz", angles_deg, degrees=True).as_matrix()


def lab_to_model_rotation_deg(up_axis: int, up_sign: int = 1, forward_axis: int | None = None,
                              forward_sign: int = 1) -> tuple[float, float, float]:
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
        :func:`loper_analysis.markers.rotate_markers` applies them: the
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
        R = np.round(_rotation_matrix(angles))
        if not np.allclose(R @ up, (0, 1, 0)):
            continue
        if forward is not None and not np.allclose(R @ forward, (1, 0, 0)):
            continue
        key = (0.0 if forward is not None else -np.trace(R), sum(a != 0 for a in angles),
               sum(abs(a) for a in angles), index)
        if best_key is None or key < best_key:
            best, best_key = angles, key
    return tuple(float(a) + 0.0 for a in best)  # + 0.0: no -0.0


# ---------------------------------------------------------------- force platforms


def plate_summary(plate: ForcePlatform, up_axis: int = 2, up_sign: int = 1, threshold_n: float = 20.0) -> PlateSummary:
    """Geometry, resting level and peak of one force platform.

    Parameters
    ----------
    plate : ForcePlatform
        As :func:`loper_analysis.io.force_platforms.read_force_platforms` returns it (lab frame, SI).
    up_axis, up_sign : int
        The lab's upward axis and sign (:func:`vertical_axis`).
    threshold_n : float
        A sample is loaded when its upward force exceeds the resting level by more than this (N).

    Returns
    -------
    PlateSummary

    Raises
    ------
    LoperInputError
        Corners or forces of the wrong shape.
    """
    from .ground_reaction import resting_level

    corners = np.asarray(plate.corners_m, dtype=float)
    F = np.asarray(plate.force_n, dtype=float)
    M = np.asarray(plate.moment_nm, dtype=float)
    if corners.shape != (4, 3) or F.ndim != 2 or F.shape[1] != 3 or M.shape != F.shape or F.shape[0] == 0:
        raise LoperInputError(f"{plate.source or 'force platform'}: plate {plate.number}: corners (4, 3) and forces "
                              f"(n, 3) expected, got {corners.shape} and {F.shape}")
    normal = _corner_normal(corners)
    up_component = float(normal[up_axis] * up_sign) if np.all(np.isfinite(normal)) else 0.0
    order = "" if abs(up_component) < np.sqrt(0.5) else ("counter-clockwise" if up_component > 0 else "clockwise")
    # resting_level takes the vertical as column 2: put the upward force there
    horizontal = [a for a in range(3) if a != up_axis]
    cols = [*horizontal, up_axis]
    v = up_sign * F[:, up_axis]
    F_up = np.column_stack([F[:, horizontal[0]], F[:, horizontal[1]], v])
    M_up = M[:, cols] * np.array([1.0, 1.0, up_sign])
    try:
        rest_f, _, _ = resting_level(F_up, M_up, source=plate.source)
        rest = float(rest_f[2])
    except LoperInputError:
        rest = None
    above = v - (rest if rest is not None else 0.0)
    k = int(np.argmax(above))
    loaded = 100.0 * float(np.mean(above > threshold_n)) if rest is not None else 100.0
    time_s = np.asarray(plate.time_s, dtype=float)
    return PlateSummary(
        number=int(plate.number), type=int(plate.type), channels=tuple(int(c) for c in plate.channels),
        corners_m=corners, centre_m=corners.mean(axis=0),
        side_lengths_m=(float(np.linalg.norm(corners[0] - corners[1])), float(np.linalg.norm(corners[0] - corners[3]))),
        normal=normal, corner_order=order, rest_vertical_n=rest, peak_vertical_n=float(above[k]),
        peak_time_s=float(time_s[k]) if time_s.size == F.shape[0] else float("nan"), loaded_pct=loaded,
    )


_CHANNEL_NAMES = {6: ("Fx", "Fy", "Fz", "Mx", "My", "Mz"),
                  8: ("Fx12", "Fx34", "Fy14", "Fy23", "Fz1", "Fz2", "Fz3", "Fz4")}


def recording_summary(rec: C3DRecording, plates: Sequence[ForcePlatform] = (), point_unit: str = "",
                      plate_problem: str = "", min_travel_m: float = 0.5) -> RecordingSummary:
    """Everything the inspection prints about one recording.

    Parameters
    ----------
    rec : C3DRecording
        Markers (m), analogs and events as read.
    plates : sequence of ForcePlatform
        The file's force platforms (empty when there are none or they cannot be read).
    point_unit : str
        ``POINT:UNITS`` as declared in the file.
    plate_problem : str
        Why the platforms could not be read, if so (printed).
    min_travel_m : float
        Least travel (m) that counts as walking through the lab (:func:`walking_direction`).

    Returns
    -------
    RecordingSummary
    """
    X = rec.markers_m
    vertical = vertical_axis(X, plates)
    walking = walking_direction(X, rec.point_rate_hz, vertical.axis, min_travel_m)
    up_only = lab_to_model_rotation_deg(vertical.axis, vertical.sign)
    forward = lab_to_model_rotation_deg(vertical.axis, vertical.sign, walking.axis, walking.sign or 1)
    owner = {}
    for p in plates:
        names = _CHANNEL_NAMES.get(len(p.channels), ())
        for i, c in enumerate(p.channels):
            owner[c - 1] = f"plate {p.number} {names[i] if i < len(names) else i + 1}"
    return RecordingSummary(
        source=rec.source, point_unit=point_unit, point_rate_hz=float(rec.point_rate_hz),
        analog_rate_hz=float(rec.analog_rate_hz), first_frame=int(rec.first_frame), n_frames=int(X.shape[0]),
        markers=marker_presence(rec.marker_labels, X, rec.point_rate_hz, rec.first_frame),
        sparse_frames=sparse_frames(X, rec.first_frame),
        n_empty_frames=int(sparse_frames(X, rec.first_frame, min_markers=1).size),
        plates=[plate_summary(p, vertical.axis, vertical.sign) for p in plates], plate_problem=plate_problem,
        n_plates_declared=int(rec.n_force_platforms), analog_labels=list(rec.analog_labels),
        analog_units=list(rec.analog_units), events=rec.events.copy(), vertical=vertical, walking=walking,
        rotation_deg=up_only, rotation_forward_deg=forward, channel_owner=owner,
    )


# ---------------------------------------------------------------- label matching


def _normalised(name: str) -> str:
    return _NOT_ALNUM.sub("", str(name).lower())


def _landmarks(name: str) -> set[tuple[str | None, str]]:
    """(side, landmark) readings of a name: unsided, leading L/R or Left/Right, trailing _l/_r."""
    flat = _normalised(name)
    readings: list[tuple[str | None, str]] = [(None, flat)]
    for word, side in (("left", "l"), ("right", "r")):
        if flat.startswith(word):
            readings.append((side, flat[len(word):]))
    if flat[:1] in ("l", "r"):
        readings.append((flat[0], flat[1:]))
    suffix = _SIDE_SUFFIX.search(str(name).strip())
    if suffix:
        readings.append((suffix.group(1).lower(), flat[:-1]))
    return {(side, _SPELLING_TO_LANDMARK[rest]) for side, rest in readings if rest in _SPELLING_TO_LANDMARK}


def _keys(name: str, rule: str) -> set:
    if rule == "exact":
        return {name}
    if rule == "case":
        return {name.lower()}
    if rule == "punctuation":
        flat = _normalised(name)
        return {flat} if flat else set()
    return _landmarks(name)


def match_labels(labels: Sequence[str], model_markers: Sequence[str]) -> LabelMatch:
    """Match a file's marker labels to a model's markers by name (rules in the module notes).

    Parameters
    ----------
    labels : sequence of str
        The file's labels, as in the file (a subject prefix ``Name:`` is stripped for matching).
    model_markers : sequence of str
        The model's marker names (repeats are ignored).

    Returns
    -------
    LabelMatch
        Pairs in file order; unmatched and ambiguous labels; model markers no label provides.
    """
    labels = [str(lab) for lab in labels]
    names = [strip_subject_prefix(lab) for lab in labels]
    markers = list(dict.fromkeys(str(m) for m in model_markers))
    matched: dict[int, tuple[str, str]] = {}
    ambiguous: dict[int, tuple[str, ...]] = {}
    for rule in _RULES:
        free = [m for m in markers if m not in {mk for mk, _ in matched.values()}]
        by_key: dict = {}
        for m in free:
            for key in _keys(m, rule):
                by_key.setdefault(key, []).append(m)
        wanted: dict[int, list[str]] = {}
        for i, name in enumerate(names):
            if i in matched or i in ambiguous:
                continue
            candidates = list(dict.fromkeys(m for key in _keys(name, rule) for m in by_key.get(key, ())))
            if candidates:
                wanted[i] = candidates
        demand: dict[str, int] = {}
        for candidates in wanted.values():
            if len(candidates) == 1:
                demand[candidates[0]] = demand.get(candidates[0], 0) + 1
        for i, candidates in wanted.items():
            if len(candidates) == 1 and demand[candidates[0]] == 1:
                matched[i] = (candidates[0], rule)
            else:
                ambiguous[i] = tuple(candidates)
    taken = {m for m, _ in matched.values()}
    return LabelMatch(
        pairs=tuple((labels[i], *matched[i]) for i in sorted(matched)),
        unmatched_labels=tuple(labels[i] for i in range(len(labels)) if i not in matched),
        ambiguous={labels[i]: ambiguous[i] for i in sorted(ambiguous)},
        unprovided_markers=tuple(m for m in markers if m not in taken),
    )


def starter_label_map(match: LabelMatch) -> pd.DataFrame:
    """The label map rows of a match: columns ``label`` (prefix stripped), ``marker``; only names that differ.

    A label already named like its marker needs no row. The table is what
    :func:`loper_analysis.io.readers.read_label_map` reads from a TSV.
    """
    rows = [(strip_subject_prefix(label), marker) for label, marker, _ in match.pairs
            if strip_subject_prefix(label) != marker]
    return pd.DataFrame(rows, columns=["label", "marker"], dtype=object)


def heel_markers(names: Sequence[str]) -> dict[str, str] | None:
    """``{"left": ..., "right": ...}``: the one heel marker of each side among ``names``; None unless both are unique.

    Heel spellings are those of :data:`LANDMARK_SYNONYMS` (``LHEE``, ``L.Heel``, ``LCAL``, ``L_FCC`` ...).
    """
    found: dict[str, list[str]] = {"l": [], "r": []}
    for name in names:
        for side, landmark in _landmarks(str(name)):
            if landmark == "heel" and side in found:
                found[side].append(str(name))
    if len(found["l"]) != 1 or len(found["r"]) != 1:
        return None
    return {"left": found["l"][0], "right": found["r"][0]}


# ---------------------------------------------------------------- config snippet


def _yaml_scalar(value) -> str:
    """A YAML flow value: JSON for strings and lists (valid YAML), whole numbers without a point."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_yaml_scalar(v) for v in value) + "]"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{k}: {_yaml_scalar(v)}" for k, v in value.items()) + "}"
    return json.dumps(value)


def config_snippet(rotation_deg: Sequence[float], label_map: str | Mapping[str, str] | None = None,
                   foot_markers: Mapping[str, str] | None = None, generic_model: str | None = None,
                   notes: Mapping[str, str] | None = None, header: Sequence[str] = ()) -> str:
    """YAML text setting the keys an inspection can suggest, each with a comment.

    Parameters
    ----------
    rotation_deg : sequence of 3 float
        ``markers.lab_to_model_rotation_deg`` (degrees).
    label_map : str or mapping, optional
        ``markers.label_map``: a file path, or the mapping inline.
    foot_markers : mapping, optional
        ``events.foot_markers`` ``{"left": ..., "right": ...}`` (model names).
    generic_model : str, optional
        ``opensim.generic_model`` (.osim).
    notes : mapping of str to str, optional
        A comment per key (``"rotation"``, ``"label_map"``, ``"foot_markers"``, ``"generic_model"``).
    header : sequence of str
        Comment lines at the top.

    Returns
    -------
    str
        The YAML document (keys under ``markers``, ``events``, ``opensim``), to be merged over the configuration.
    """
    notes = dict(notes or {})

    def line(key: str, value, note: str) -> str:
        text = f"  {key}: {_yaml_scalar(value)}"
        return text + (f"   # {note}" if note else "")

    out = [f"# {h}" for h in header]
    out += ["markers:", line("lab_to_model_rotation_deg", [float(a) for a in rotation_deg], notes.get("rotation", ""))]
    if isinstance(label_map, Mapping):
        if label_map:
            out.append("  label_map:" + (f"   # {notes['label_map']}" if notes.get("label_map") else ""))
            out += [f"    {_yaml_scalar(str(k))}: {_yaml_scalar(str(v))}" for k, v in label_map.items()]
        else:
            out.append("  label_map: {}" + (f"   # {notes['label_map']}" if notes.get("label_map") else ""))
    elif label_map is not None:
        out.append(line("label_map", str(label_map), notes.get("label_map", "")))
    if foot_markers:
        out += ["events:", line("foot_markers", {"left": foot_markers["left"], "right": foot_markers["right"]},
                                notes.get("foot_markers", ""))]
    if generic_model is not None:
        out += ["opensim:", line("generic_model", str(generic_model), notes.get("generic_model", ""))]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- text


def _xyz(v, digits: int = 3) -> str:
    return "(" + ", ".join(f"{float(x) + 0.0:.{digits}f}".replace("-0." + "0" * digits, "0." + "0" * digits)
                           for x in v) + ")"


def _ranges(frames: np.ndarray, limit: int = 6) -> str:
    """'0-56, 1050-1102' for sorted frame numbers (at most ``limit`` ranges, then '...')."""
    if frames.size == 0:
        return ""
    breaks = np.flatnonzero(np.diff(frames) != 1)
    starts = np.concatenate([[frames[0]], frames[breaks + 1]])
    ends = np.concatenate([frames[breaks], [frames[-1]]])
    parts = [f"{a}" if a == b else f"{a}-{b}" for a, b in zip(starts, ends)]
    more = len(parts) - limit
    return ", ".join(parts[:limit]) + (f", ... ({more} more ranges)" if more > 0 else "")


def _rotation_text(angles: Sequence[float]) -> str:
    return "[" + ", ".join(f"{a:g}" for a in angles) + "]"


def _model_axis(rotation_deg: Sequence[float], axis: int, sign: int) -> str:
    """Where the lab direction ``sign`` x axis ``axis`` points after the rotation (``"-X"`` ...)."""
    v = np.zeros(3)
    v[axis] = sign
    r = np.round(_rotation_matrix(rotation_deg) @ v)
    k = int(np.argmax(np.abs(r)))
    return axis_name(k, int(r[k]))


def format_summary(s: RecordingSummary) -> str:
    """The inspection of one recording as plain text (units stated on every line that has numbers)."""
    rate = s.point_rate_hz
    last = s.first_frame + s.n_frames - 1
    lines = [
        f"File {s.source}",
        f"  markers   {rate:g} Hz, POINT:UNITS {s.point_unit or '(none)'} (shown below in m)",
        f"  analogs   {s.analog_rate_hz:g} Hz ({round(s.analog_rate_hz / rate)} samples per frame), "
        f"{len(s.analog_labels)} channel(s)",
        f"  frames    {s.n_frames}, first frame {s.first_frame} (0-based) at {s.first_time_s:.3f} s, last frame "
        f"{last} at {last / rate:.3f} s; duration {s.duration_s:.3f} s ({s.n_frames} frames / {rate:g} Hz)",
        "",
    ]
    m = s.markers
    width = max([len(lab) for lab in m["label"]] + [5])
    if len(m):
        lines.append(f"Markers: {len(m)} label(s); present = % of the {s.n_frames} frames; first and last present "
                     "frame; longest gap = missing frames between them")
        lines.append(f"  {'label':<{width}}  present %  first  last   longest gap")
    else:
        lines.append("Markers: none")
    for row in m.itertuples(index=False):
        if row.n_present == 0:
            lines.append(f"  {row.label:<{width}}  {0.0:9.1f}  never present")
            continue
        gap = "none" if row.longest_gap_frames == 0 else \
            f"{row.longest_gap_frames} frames ({row.longest_gap_s:.3f} s)"
        lines.append(f"  {row.label:<{width}}  {row.present_pct:9.1f}  {int(row.first_present_frame):5d}  "
                     f"{int(row.last_present_frame):5d}  {gap}")
    n_sparse = s.sparse_frames.size
    lines.append(f"  frames with fewer than {MIN_MARKERS_PER_FRAME} markers: {n_sparse} of {s.n_frames}"
                 + (f" (frames {_ranges(s.sparse_frames)}; {s.n_empty_frames} of them without any marker; "
                    "inverse kinematics cannot use them)" if n_sparse else ""))
    lines.append("")

    if s.plates:
        lines.append(f"Force platforms: {len(s.plates)} (forces on the body, lab frame; vertical = "
                     f"{axis_name(s.vertical.axis, s.vertical.sign)})")
    elif s.n_plates_declared:
        lines.append(f"Force platforms: {s.n_plates_declared} declared, not readable: {s.plate_problem}")
    else:
        lines.append("Force platforms: none (no FORCE_PLATFORM group; events then need events.grf_channels)")
    for p in s.plates:
        lines.append(f"  plate {p.number}: TYPE {p.type}, analog channels {', '.join(map(str, p.channels))}")
        lines.append("    corners (lab, m): " + " ".join(_xyz(c) for c in p.corners_m))
        lines.append(f"    size {p.side_lengths_m[0]:.3f} x {p.side_lengths_m[1]:.3f} m, centre {_xyz(p.centre_m)} m")
        order = f"corners listed {p.corner_order} seen from above" if p.corner_order else \
            "the plate does not face up or down"
        lines.append(f"    normal from the corners (right-hand rule of their order): {_xyz(p.normal)}: {order}")
        if p.rest_vertical_n is None:
            lines.append("    resting vertical level: none (the plate is loaded throughout)")
            lines.append(f"    peak vertical force {p.peak_vertical_n:.1f} N at {p.peak_time_s:.3f} s (as read)")
        else:
            lines.append(f"    resting (unloaded) vertical level {p.rest_vertical_n:.1f} N; loaded (> 20 N above it) "
                         f"{p.loaded_pct:.1f} % of the time")
            lines.append(f"    peak vertical force {p.peak_vertical_n:.1f} N above rest at {p.peak_time_s:.3f} s "
                         f"({p.peak_vertical_n + p.rest_vertical_n:.1f} N as read)")
    lines.append("")

    lines.append(f"Analog channels: {len(s.analog_labels)}, all at {s.analog_rate_hz:g} Hz")
    if s.analog_labels:
        width = max(len(lab) for lab in s.analog_labels)
        for i, (lab, unit) in enumerate(zip(s.analog_labels, s.analog_units)):
            owner = s.channel_owner.get(i, "")
            lines.append(f"  {i + 1:3d}  {lab:<{width}}  {unit or '(no unit)':<8}" + (f"  {owner}" if owner else ""))
    lines.append("")

    if len(s.events):
        lines.append(f"Events: {len(s.events)} (EVENT group; time on the file's clock, s)")
        for ev in s.events.itertuples(index=False):
            lines.append(f"  {ev.context:<8} {ev.label:<16} {ev.time_s:8.3f} s  (frame {round(ev.time_s * rate)})")
    else:
        lines.append("Events: none")
    lines.append("")

    v, w = s.vertical, s.walking
    lines.append("Lab frame")
    text = f"  vertical axis: {axis_name(v.axis, v.sign)} " + \
        ("(assumed: neither plates nor markers tell)" if v.basis == "assumed" else f"(from the {v.basis})")
    if v.marker_axis is not None:
        spread = ", ".join(f"{AXIS_NAMES[a]} {v.marker_spread_m[a]:.2f}" for a in range(3))
        agree = "agree" if (v.marker_axis, v.marker_sign) == (v.axis, v.sign) else \
            f"say {axis_name(v.marker_axis, v.marker_sign)}: check"
        text += f"; the markers {agree} (median spread of a frame's markers, m: {spread})"
    lines.append(text)
    if w.axis is None and not np.all(np.isfinite(w.travel_m)):
        lines.append("  walking direction: unknown (no marker is present in two frames)")
    elif w.axis is None:
        travel = ", ".join(f"{AXIS_NAMES[a]} {w.travel_m[a]:+.2f}" for a in range(3))
        lines.append(f"  walking direction: treadmill/standing (the markers do not travel; median travel, m: {travel})")
    else:
        lines.append(f"  walking direction: {axis_name(w.axis, w.sign)} (the markers travel "
                     f"{w.travel_m[w.axis]:+.2f} m along {AXIS_NAMES[w.axis]} at {w.speed_m_per_s:.2f} m/s)")
    lines.append(f"  suggested markers.lab_to_model_rotation_deg: {_rotation_text(s.rotation_deg)} (degrees about the "
                 "fixed X, Y, Z: up -> model +Y)")
    if w.axis is None:
        lines.append("  (the facing direction is not known: check that the subject faces model +X, OpenSim's forward, "
                     "after the rotation)")
    elif tuple(s.rotation_forward_deg) == tuple(s.rotation_deg):
        lines.append("  (this trial then walks toward model +X, OpenSim's forward)")
    else:
        lines.append(f"  (this trial then walks toward model {_model_axis(s.rotation_deg, w.axis, w.sign)}; "
                     f"{_rotation_text(s.rotation_forward_deg)} also turns its walking direction to model +X, "
                     "OpenSim's forward)")
    return "\n".join(line.rstrip() for line in lines) + "\n"


def format_label_match(match: LabelMatch, model_name: str, n_model_markers: int) -> str:
    """The matching of a file's labels to a model's markers as plain text."""
    lines = [f"Labels and model markers ({model_name}: {n_model_markers} markers)"]
    lines.append(f"  matched: {len(match.pairs)} label(s)")
    if match.pairs:
        width = max(len(lab) for lab, _, _ in match.pairs)
        for label, marker, rule in match.pairs:
            lines.append(f"    {label:<{width}} -> {marker:<20} ({rule})")
    if match.ambiguous:
        lines.append(f"  ambiguous (left unmatched): {len(match.ambiguous)}")
        for label, candidates in match.ambiguous.items():
            lines.append(f"    {label}: {' or '.join(candidates)}" if len(candidates) > 1 else
                         f"    {label}: {candidates[0]} (wanted by more than one label)")
    for title, names in (("labels without a model marker", match.unmatched_labels),
                         ("model markers no label provides", match.unprovided_markers)):
        lines.append(f"  {title}: {len(names)}")
        if names:
            lines += textwrap.wrap(", ".join(names), width=100, initial_indent="    ", subsequent_indent="    ",
                                   break_on_hyphens=False)
    return "\n".join(lines) + "\n"
