"""What a lab's C3D file holds: markers, force platforms, channels and events, summarised and printed.

The library side of ``loper-analysis inspect`` (the file side is
:mod:`loper_analysis.stages.inspect`). Every function takes arrays or
records already read (:class:`~loper_analysis.io.c3d.C3DRecording`,
:class:`~loper_analysis.io.force_platforms.ForcePlatform`) and returns new
objects; :func:`loper_analysis.inspection_text.format_summary` and
:func:`~loper_analysis.inspection_text.format_label_match` turn them into plain text and :func:`config_snippet`
into YAML. The lab's axes and
the suggested rotation come from :mod:`loper_analysis.motion.lab_frame`, the
matching of labels to model markers from :mod:`loper_analysis.motion.label_matching`.

Marker presence (:func:`marker_presence`)
    A marker is present in a frame when its three coordinates are finite
    (the reader's missing points are NaN). The longest gap is the longest
    run of missing frames between the marker's first and last present
    frame; frames before the first and after the last present frame are
    described by those two frame numbers instead. Frame numbers are the
    file's own (0-based, ``first_frame + k`` for row ``k``).

Force platforms (:func:`plate_summary`)
    The normal is the right-hand normal of the corners in file order
    (:func:`loper_analysis.motion.lab_frame.corner_normal`, ``(c3 - c1) x (c4 -
    c2)``, unit length): it points down for corners listed clockwise seen
    from above, the order the C3D format gives (its plate z axis points
    down), and up for corners listed counter-clockwise. Either order is
    reported, neither is refused. The resting level is
    :func:`loper_analysis.gait.grf.resting_level` of the force along
    the lab's upward axis; a plate loaded throughout has none.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from loper_analysis.checks import marker_array
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.lab_frame import (
    VerticalAxis,
    WalkingDirection,
    corner_normal,
    lab_to_model_rotation_deg,
    vertical_axis,
    walking_direction,
)

if TYPE_CHECKING:  # records only; nothing is read here
    from loper_analysis.io.c3d import C3DRecording
    from loper_analysis.io.force_platforms import ForcePlatform

__all__ = [
    "yaml_flow",
    "MAX_CUTOFF_RATE_FRACTION",
    "MIN_MARKERS_PER_FRAME",
    "PlateSummary",
    "RecordingSummary",
    "config_snippet",
    "marker_cutoff_hz",
    "marker_presence",
    "measurement_losses",
    "plate_summary",
    "recording_summary",
    "sparse_frames",
]

#: Fewest markers in a frame for inverse kinematics to place the model.
MIN_MARKERS_PER_FRAME = 3


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


# ---------------------------------------------------------------- markers


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
    X = marker_array(markers_m)
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
            inner = ~present[idx[0] : idx[-1] + 1, j]
            gap = max((b - a for a, b in _runs(inner)), default=0)
        rows.append(
            {
                "label": str(label),
                "n_present": int(idx.size),
                "present_pct": 100.0 * idx.size / n_frames if n_frames else 0.0,
                "first_present_frame": first,
                "last_present_frame": last,
                "longest_gap_frames": int(gap),
                "longest_gap_s": gap / float(point_rate_hz),
            }
        )
    table = pd.DataFrame(
        rows,
        columns=[
            "label",
            "n_present",
            "present_pct",
            "first_present_frame",
            "last_present_frame",
            "longest_gap_frames",
            "longest_gap_s",
        ],
    )
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
    X = marker_array(markers_m)
    count = np.all(np.isfinite(X), axis=2).sum(axis=1)
    return np.flatnonzero(count < min_markers) + int(first_frame)


# ---------------------------------------------------------------- force platforms


def plate_summary(plate: ForcePlatform, up_axis: int = 2, up_sign: int = 1, threshold_n: float = 20.0) -> PlateSummary:
    """Geometry, resting level and peak of one force platform.

    Parameters
    ----------
    plate : ForcePlatform
        As :func:`loper_analysis.io.force_platforms.read_force_platforms` returns it (lab frame, SI).
    up_axis, up_sign : int
        The lab's upward axis and sign (:func:`loper_analysis.motion.lab_frame.vertical_axis`).
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
    from loper_analysis.gait.grf import resting_level

    corners = np.asarray(plate.corners_m, dtype=float)
    F = np.asarray(plate.force_n, dtype=float)
    M = np.asarray(plate.moment_nm, dtype=float)
    if corners.shape != (4, 3) or F.ndim != 2 or F.shape[1] != 3 or M.shape != F.shape or F.shape[0] == 0:
        raise LoperInputError(
            f"{plate.source or 'force platform'}: plate {plate.number}: corners (4, 3) and forces "
            f"(n, 3) expected, got {corners.shape} and {F.shape}"
        )
    normal = corner_normal(corners)
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
        number=int(plate.number),
        type=int(plate.type),
        channels=tuple(int(c) for c in plate.channels),
        corners_m=corners,
        centre_m=corners.mean(axis=0),
        side_lengths_m=(float(np.linalg.norm(corners[0] - corners[1])), float(np.linalg.norm(corners[0] - corners[3]))),
        normal=normal,
        corner_order=order,
        rest_vertical_n=rest,
        peak_vertical_n=float(above[k]),
        peak_time_s=float(time_s[k]) if time_s.size == F.shape[0] else float("nan"),
        loaded_pct=loaded,
    )


_CHANNEL_NAMES = {
    6: ("Fx", "Fy", "Fz", "Mx", "My", "Mz"),
    8: ("Fx12", "Fx34", "Fy14", "Fy23", "Fz1", "Fz2", "Fz3", "Fz4"),
}


def recording_summary(
    rec: C3DRecording,
    plates: Sequence[ForcePlatform] = (),
    point_unit: str = "",
    plate_problem: str = "",
    min_travel_m: float = 0.5,
) -> RecordingSummary:
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
        Least travel (m) that counts as walking through the lab
        (:func:`loper_analysis.motion.lab_frame.walking_direction`).

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
        source=rec.source,
        point_unit=point_unit,
        point_rate_hz=float(rec.point_rate_hz),
        analog_rate_hz=float(rec.analog_rate_hz),
        first_frame=int(rec.first_frame),
        n_frames=int(X.shape[0]),
        markers=marker_presence(rec.marker_labels, X, rec.point_rate_hz, rec.first_frame),
        sparse_frames=sparse_frames(X, rec.first_frame),
        n_empty_frames=int(sparse_frames(X, rec.first_frame, min_markers=1).size),
        plates=[plate_summary(p, vertical.axis, vertical.sign) for p in plates],
        plate_problem=plate_problem,
        n_plates_declared=int(rec.n_force_platforms),
        analog_labels=list(rec.analog_labels),
        analog_units=list(rec.analog_units),
        events=rec.events.copy(),
        vertical=vertical,
        walking=walking,
        rotation_deg=up_only,
        rotation_forward_deg=forward,
        channel_owner=owner,
    )


# ---------------------------------------------------------------- config snippet


def yaml_flow(value) -> str:
    """A YAML flow value: JSON for strings and lists (valid YAML), whole numbers without a point."""
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(yaml_flow(v) for v in value) + "]"
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{k}: {yaml_flow(v)}" for k, v in value.items()) + "}"
    return json.dumps(value)


def config_snippet(
    rotation_deg: Sequence[float],
    label_map: str | Mapping[str, str] | None = None,
    foot_markers: Mapping[str, str] | None = None,
    generic_model: str | None = None,
    notes: Mapping[str, str] | None = None,
    header: Sequence[str] = (),
) -> str:
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
        ``model.generic_model`` (.osim).
    notes : mapping of str to str, optional
        A comment per key (``"rotation"``, ``"label_map"``, ``"foot_markers"``, ``"generic_model"``).
    header : sequence of str
        Comment lines at the top.

    Returns
    -------
    str
        The YAML document (keys under ``markers``, ``events``, ``model``), to be merged over the configuration.
    """
    notes = dict(notes or {})

    def line(key: str, value, note: str) -> str:
        text = f"  {key}: {yaml_flow(value)}"
        return text + (f"   # {note}" if note else "")

    out = [f"# {h}" for h in header]
    out += ["markers:", line("lab_to_model_rotation_deg", [float(a) for a in rotation_deg], notes.get("rotation", ""))]
    if isinstance(label_map, Mapping):
        if label_map:
            out.append("  label_map:" + (f"   # {notes['label_map']}" if notes.get("label_map") else ""))
            out += [f"    {yaml_flow(str(k))}: {yaml_flow(str(v))}" for k, v in label_map.items()]
        else:
            out.append("  label_map: {}" + (f"   # {notes['label_map']}" if notes.get("label_map") else ""))
    elif label_map is not None:
        out.append(line("label_map", str(label_map), notes.get("label_map", "")))
    if foot_markers:
        out += [
            "events:",
            line(
                "foot_markers",
                {"left": foot_markers["left"], "right": foot_markers["right"]},
                notes.get("foot_markers", ""),
            ),
        ]
    if generic_model is not None:
        out += ["model:", line("generic_model", str(generic_model), notes.get("generic_model", ""))]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------- text


# ---------------------------------------------------------------- what a subject's config may hold

#: Highest low-pass cut-off ``inspect`` writes, as a fraction of the lowest marker rate of the walking trials:
#: 0.4 of the rate is 0.8 of the Nyquist frequency (half the rate), which the filter must stay below
#: (:func:`loper_analysis.filtering.check_cutoff` refuses a cut-off at or above it).
MAX_CUTOFF_RATE_FRACTION = 0.4


def marker_cutoff_hz(configured_hz: float | None, rates_hz: Sequence[float]) -> tuple[float | None, str]:
    """The walking trials' marker low-pass cut-off ``inspect`` writes (``markers.filter.cutoff_hz``) and why.

    The rule: ``min(configured, MAX_CUTOFF_RATE_FRACTION * lowest rate)``. A cut-off must lie below the
    Nyquist frequency ``rate / 2`` of every trial filtered; 0.4 of the rate (0.8 of the Nyquist frequency)
    keeps it there with a margin in which the order-4 zero-phase filter still attenuates (its gain at 0.9 of
    the Nyquist frequency is below 0.01 when the cut-off is 0.4 of the rate). The configured cut-off (40 Hz by
    default) stands at every rate of 100 Hz and above.

    Parameters
    ----------
    configured_hz : float or None
        The configuration's cut-off (Hz); None or 0: no filter (returned as None).
    rates_hz : sequence of float
        Marker rates of the walking trials (Hz).

    Returns
    -------
    (float or None, str)
        The cut-off (Hz) and a comment naming the rule and the numbers.
    """
    if not configured_hz:
        return None, "no low-pass, as configured"
    configured = float(configured_hz)
    if not len(rates_hz):
        return configured, "as configured (no walking trial)"
    rate = float(min(rates_hz))
    limit = MAX_CUTOFF_RATE_FRACTION * rate
    cutoff = min(configured, limit)
    why = (
        f"min(configured {configured:g}, {MAX_CUTOFF_RATE_FRACTION:g} x {rate:g} Hz markers = {limit:g}) Hz: "
        f"below the Nyquist frequency {rate / 2:g} Hz"
    )
    return float(f"{cutoff:.6g}"), why


def measurement_losses(
    measurements: Mapping[str, tuple[Sequence[tuple[str, str]], Sequence[str]]],
    template_markers: Sequence[str],
    static_markers: Sequence[str],
    scaled: Sequence[str],
) -> list[str]:
    """Lines saying which scaling pairs a static trial's markers drop and which measurements lose every pair.

    Parameters
    ----------
    measurements : mapping
        Name -> (marker pairs, bodies), the template's.
    template_markers : sequence of str
        The template's markers: only a pair naming one of them that the static trial lacks counts as dropped.
    static_markers : sequence of str
        The template markers the static trial provides.
    scaled : sequence of str
        The measurements the written ScaleTool setup holds.

    Returns
    -------
    list of str
        One line per measurement that lost a pair (or all of them); empty when nothing is lost.
    """
    known, present, kept = set(template_markers), set(static_markers), set(scaled)
    lines = []
    for name, (pairs, bodies) in measurements.items():
        lost = [(a, b) for a, b in pairs if any(m in known and m not in present for m in (a, b))]
        absent = sorted({m for pair in lost for m in pair if m in known and m not in present})
        if name not in kept:
            lines.append(
                f"measurement {name}: no pair left ({', '.join(f'{a}-{b}' for a, b in pairs)}; the static trial "
                f"lacks {', '.join(absent) or 'their markers'}): the generic size of {', '.join(bodies)} is kept"
            )
        elif lost:
            lines.append(
                f"measurement {name}: pair(s) {', '.join(f'{a}-{b}' for a, b in lost)} left out (the static trial "
                f"lacks {', '.join(absent)})"
            )
    return lines
