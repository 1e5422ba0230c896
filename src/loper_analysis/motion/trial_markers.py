"""A trial's markers prepared for OpenSim: named as the model's, cropped, gaps filled, turned into the model's
frame and low-passed (:func:`prepared_markers`), with a per-marker summary; :class:`MarkerSettings` says how.
"""

from __future__ import annotations

import dataclasses
import logging
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG, MIN_IK_MARKERS
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import CUTOFF_HZ, ORDER, lowpass_finite_runs
from loper_analysis.motion.heading import MIN_TRAVEL_SPEED_M_PER_S, trial_heading
from loper_analysis.motion.knee_alignment import kad_knee_markers
from loper_analysis.motion.label_matching import landmark_indices
from loper_analysis.motion.level_walking import level_walking_warning, pelvis_height_change_m, plate_heights_m
from loper_analysis.motion.marker_names import model_marker_names, require_model_markers
from loper_analysis.motion.markers import MAX_GAP_FRAMES, fill_gaps, gap_summary, lab_up, rotate_markers
from loper_analysis.motion.plausibility import EXTENT_RANGE_M, require_marker_extent

__all__ = ["MarkerSettings", "PreparedMarkers", "TRIAL_MARKER_COLUMNS", "prepared_markers"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MarkerSettings:
    """How a trial's markers are named, cropped, filled, turned and filtered (config ``markers.*``, with its
    ``filter``).

    ``rotation_deg``: lab -> model rotation about the fixed X, Y, Z axes (degrees); ``walking_direction``:
    ``"auto"`` turns a travelling trial to walk along the model's +X, ``"fixed"`` keeps ``rotation_deg``;
    ``min_travel_speed_m_per_s``: the speed from which a trial travels (m/s); ``max_gap_frames``: interior gaps
    up to this many frames are filled (0: none); ``cutoff_hz``, ``order``: the zero-phase Butterworth low-pass
    (Hz; None or 0: none); ``extent_range_m``: the markers' largest distance (m) a file in the declared unit
    can have; ``label_map``: {lab label: model marker}, a file, or a sequence of them merged in order;
    ``span_s``: (start, end) on the file's clock (s) or None; ``duration_s``: keep the first seconds or None;
    ``required_markers``: model markers that must be found, or None; ``trial_label_maps``: a trial kind's or
    trial's label map (by kind or name) added to ``label_map``, and ``trial_spans_s``: a trial's span (by
    ``{subject}/{trial}`` or trial name), both for :meth:`for_trial` (empty: none).
    """

    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    walking_direction: str = "auto"
    min_travel_speed_m_per_s: float = MIN_TRAVEL_SPEED_M_PER_S
    max_gap_frames: int = MAX_GAP_FRAMES
    cutoff_hz: float | None = CUTOFF_HZ
    order: int = ORDER
    extent_range_m: tuple[float, float] = EXTENT_RANGE_M
    label_map: Mapping[str, str] | str | os.PathLike | Sequence | None = None
    span_s: tuple[float, float] | None = None
    duration_s: float | None = None
    required_markers: tuple[str, ...] | None = None
    trial_label_maps: Mapping[str, Mapping[str, str] | str] = dataclasses.field(default_factory=dict)
    trial_spans_s: Mapping[str, Sequence[float]] = dataclasses.field(default_factory=dict)

    def label_maps(self, trial: str, kind: str) -> list:
        """The label maps of ``trial`` (of kind ``kind``), merged in this order: ``label_map``, then the kind's and
        the trial's of ``trial_label_maps`` (each a mapping or a file's path)."""
        per_trial = self.trial_label_maps
        return [m for m in (self.label_map, per_trial.get(kind), per_trial.get(trial)) if m]

    def for_trial(self, subject: str, trial: str, kind: str) -> MarkerSettings:
        """The settings of one trial: its label maps (:meth:`label_maps`) as ``label_map``, its span as ``span_s``
        (``trial_spans_s`` by ``{subject}/{trial}``, else by trial name), no per-trial tables."""
        spans = self.trial_spans_s
        span = spans.get(f"{subject}/{trial}", spans.get(trial))
        return dataclasses.replace(
            self,
            label_map=tuple(self.label_maps(trial, kind)) or None,
            span_s=None if span is None else tuple(span),
            trial_label_maps={},
            trial_spans_s={},
        )

    def for_static(self) -> MarkerSettings:
        """The static trial's settings: neither filled nor filtered (scaling averages each marker over the frames
        it is present in, as OpenSim's ScaleTool reads a lab's static trial)."""
        return dataclasses.replace(self, max_gap_frames=0, cutoff_hz=None)


@dataclass(frozen=True)
class PreparedMarkers:
    """A trial's markers ready for a TRC: ``time_s`` (n,) on the file's clock, ``markers_m`` (n, m, 3) in the
    model's frame (m; NaN where missing), the model's marker ``names`` (m), the filled ``gaps`` (one row per
    gap) and the per-marker ``summary`` (:data:`TRIAL_MARKER_COLUMNS`)."""

    time_s: np.ndarray
    markers_m: np.ndarray
    names: list[str]
    gaps: pd.DataFrame
    summary: pd.DataFrame


def prepared_markers(
    rec, label_map, settings: MarkerSettings, source: str, plate_corners_m: Sequence = ()
) -> PreparedMarkers:
    """The markers of a recording (:class:`loper_analysis.io.c3d.C3DRecording`) named by ``label_map`` (one
    mapping {lab label: model marker}, or several merged in order), cropped, filled, turned and low-passed as
    ``settings`` says (:func:`loper_analysis.stages.markers.step.markers` tells each step).

    Before the trial's heading and speed, a trial that is not level walking is warned about
    (:mod:`loper_analysis.motion.level_walking`: its pelvis markers' rise or fall, the heights of the force
    plates whose corners ``plate_corners_m`` gives, (4, 3) each, m, lab frame); the summary holds the figures
    and the warning.

    Raises
    ------
    LoperInputError
        No markers, a required marker missing, an empty span, markers in another unit, a filter the rate
        cannot hold: naming ``source``.
    """
    s = settings
    _require_markers(rec, source)
    names = model_marker_names(rec.marker_labels, label_map, source)
    names, raw, added = kad_knee_markers(names, rec.markers_m, source=source)
    labels = list(rec.marker_labels) + [f"{knee} (knee alignment device)" for knee in added]
    for knee in added:
        log.info("%s: %s from the knee alignment device (its origin on the lateral epicondyle)", source, knee)
    if s.required_markers is not None:
        require_model_markers(names, s.required_markers, source, labels)
    time_s = rec.time_s
    if s.duration_s is not None:
        keep = time_s < time_s[0] + s.duration_s - 1e-9
        time_s, raw = time_s[keep], raw[keep]
    if s.span_s is not None:
        time_s, raw = _cropped(time_s, raw, s.span_s, source)
    require_marker_extent(raw, source, s.extent_range_m)
    level = _level_walking(raw, names, rec.point_rate_hz, s.rotation_deg, plate_corners_m, source)
    heading = _heading(raw, names, rec.point_rate_hz, s, source)
    filled, gaps = fill_gaps(raw, s.max_gap_frames, names, source=source, unfillable="keep")
    X = rotate_markers(filled, heading.rotation_deg)
    _require_upright(X, names, s.rotation_deg, heading.rotation_deg, source)
    unfiltered = None
    if s.cutoff_hz:
        try:
            X, unfiltered = lowpass_finite_runs(
                X,
                rec.point_rate_hz,
                s.cutoff_hz,
                s.order,
                axis=0,
                setting="markers.filter.cutoff_hz",
                rate_name="POINT:RATE",
            )
        except LoperInputError as exc:
            raise LoperInputError(f"{source}: markers: {exc}") from None
    summary = _trial_marker_summary(gap_summary(raw, X, names, unfiltered), labels, time_s, X, heading)
    for column, value in zip(LEVEL_WALKING_COLUMNS, level, strict=True):
        summary[column] = value
    log.info(
        "%s: %d frames at %g Hz, %d markers, %d gap(s) filled",
        source,
        len(time_s),
        rec.point_rate_hz,
        len(names),
        len(gaps),
    )
    return PreparedMarkers(time_s, X, names, gaps, summary)


def _require_markers(rec, source: str) -> None:
    """Refuse a recording without marker trajectories; note the points that are not markers, left out."""
    if not rec.marker_labels:
        others = f" and {len(rec.output_labels)} computed point(s) ({', '.join(rec.output_labels[:4])}, ...)" * bool(
            rec.output_labels
        )
        channels = ", ".join(rec.analog_labels[:6]) + (", ..." if len(rec.analog_labels) > 6 else "")
        raise LoperInputError(
            f"{source}: no markers (POINT:LABELS holds no marker trajectory): the file holds "
            f"{len(rec.analog_labels)} analog channel(s) ({channels or 'none'}){others}; export the trial with "
            "its marker trajectories"
        )
    if rec.output_labels:
        kinds = pd.Series(rec.output_kinds).value_counts()
        log.info(
            "%s: %d point(s) that are not markers left out (%s)",
            source,
            len(rec.output_labels),
            ", ".join(f"{k} {n}" for k, n in kinds.items()),
        )


def _require_upright(X: np.ndarray, names: list[str], rotation_deg, turned_deg, source: str) -> None:
    """Stop when the lab-to-model rotation hangs the subject upside down, warn when it lays it down: the markers' up
    (feet to pelvis, :func:`loper_analysis.motion.upright.markers_up`) more than
    :data:`~loper_analysis.motion.upright.MAX_UPSIDE_DOWN_DEG` from the model's +Y is nearest its -Y (a stop);
    more than :data:`~loper_analysis.motion.upright.MAX_TILT_DEG`, nearest a horizontal axis (a warning: the lab's
    frame kept as it is, ``[0, 0, 0]``, is a way to compare with another reader). ``X``: the markers turned by
    ``turned_deg`` (``rotation_deg`` and the trial's turn about the vertical); the rotation offered instead is
    ``rotation_deg``'s. Not judged (logged) without a pelvis marker and a foot marker, or when the frames'
    feet-to-pelvis directions disagree (below :data:`~loper_analysis.motion.upright.MIN_AGREEMENT`: no body)."""
    from loper_analysis.motion.upright import (
        MAX_TILT_DEG,
        MAX_UPSIDE_DOWN_DEG,
        MIN_AGREEMENT,
        markers_up,
        nearest_axis,
        upright_rotation_deg,
    )

    upper = landmark_indices(names, ["asis", "psis", "sacrum"])
    lower = landmark_indices(names, ["heel", "toe", "mt1", "mt5", "ankle_lateral", "ankle_medial"])
    up, n, agreement = markers_up(X, upper, lower)
    if not n or agreement < MIN_AGREEMENT:
        log.info(
            "%s: the subject's up is not checked: %s",
            source,
            "no frame with a pelvis marker and a foot marker"
            if not n
            else f"the feet-to-pelvis directions of its frames disagree (agreement {agreement:.2f}, at least "
            f"{MIN_AGREEMENT:g} for a body)",
        )
        return
    tilt = float(np.degrees(np.arccos(np.clip(up[1], -1.0, 1.0))))
    log.info("%s: the markers' up (feet to pelvis) lies %.1f deg from the model's +Y", source, tilt)
    if tilt <= MAX_TILT_DEG:
        return
    lab = up @ rotate_markers(np.eye(3), turned_deg).T  # back to the lab: R.T @ up
    axis = nearest_axis(rotate_markers(lab, rotation_deg))
    given = ", ".join(f"{v:g}" for v in rotation_deg)
    better = ", ".join(f"{v:g}" for v in upright_rotation_deg(rotation_deg, axis))
    said = (
        f"{source}: markers.lab_to_model_rotation_deg (--rotate-deg) [{given}] does not stand the subject up: "
        f"its pelvis lies along the model's {axis} from its feet ({tilt:.0f} deg from the model's up, +Y; mean "
        f"over {n} frames), so the markers' up is model {axis}: try [{better}]"
    )
    if tilt > MAX_UPSIDE_DOWN_DEG:
        raise LoperInputError(said)
    log.warning("%s (the subject lies on its side or its back, more than %g deg from +Y)", said, MAX_TILT_DEG)


def _heading(raw: np.ndarray, names: list[str], rate_hz: float, s: MarkerSettings, source: str):
    """The trial's heading and the lab-to-model rotation (:func:`loper_analysis.motion.heading.trial_heading`)."""
    pelvis = (landmark_indices(names, ["asis"]), landmark_indices(names, ["psis", "sacrum"]))
    heading = trial_heading(
        raw, rate_hz, s.rotation_deg, s.walking_direction, s.min_travel_speed_m_per_s, source, pelvis
    )
    if heading.turn_deg and heading.source == "pelvis":
        log.info(
            "%s: turned %g deg about the vertical to face the model's +X (pelvis markers)", source, heading.turn_deg
        )
    elif heading.turn_deg:
        log.info(
            "%s: walks %.1f deg from the model's +X at %.2f m/s: turned %g deg about the vertical (rotation %s deg)",
            source,
            heading.heading_deg,
            heading.speed_m_per_s,
            heading.turn_deg,
            list(heading.rotation_deg),
        )
    return heading


def _level_walking(raw, names, rate_hz: float, rotation_deg, plate_corners_m, source: str):
    """The pelvis's rise or fall (m), the plates' height range (m) and the warning of a trial that is not level
    walking ('' for a level walk), logged (:mod:`loper_analysis.motion.level_walking`)."""
    up = lab_up(rotation_deg)
    change = pelvis_height_change_m(raw, names, rate_hz, up)
    heights = plate_heights_m(plate_corners_m, up)
    said = level_walking_warning(change, heights)
    if said:
        log.warning("%s: %s", source, said)
    return change, float(np.ptp(heights)) if heights.size else np.nan, said


#: The trial's level-walking figures and warning in the markers summary (:func:`prepared_markers`).
LEVEL_WALKING_COLUMNS: tuple[str, ...] = ("pelvis_height_change_m", "plate_height_range_m", "warnings")


#: Columns the markers summary adds to :data:`loper_analysis.motion.markers.GAP_SUMMARY_COLUMNS`: the marker's lab
#: label, then facts of the whole trial repeated on each row (like ``n_frames``).
TRIAL_MARKER_COLUMNS: tuple[str, ...] = (
    "label",
    "n_frames_too_few_markers",
    "first_time_s",
    "last_time_s",
    "heading_deg",
    "speed_m_per_s",
    "turn_deg",
    "rotation_x_deg",
    "rotation_y_deg",
    "rotation_z_deg",
    *LEVEL_WALKING_COLUMNS,
)


def _trial_marker_summary(per_marker: pd.DataFrame, labels: Sequence[str], time_s, markers_m, heading) -> pd.DataFrame:
    """The per-marker gap summary with the lab labels and the trial's facts (:data:`TRIAL_MARKER_COLUMNS`)."""
    present = np.all(np.isfinite(np.asarray(markers_m, float)), axis=2)
    out = per_marker.copy()
    out.insert(0, "label", [str(lab) for lab in labels])
    out["n_frames_too_few_markers"] = int((present.sum(axis=1) < MIN_IK_MARKERS).sum())
    out["first_time_s"] = float(time_s[0]) if len(time_s) else np.nan
    out["last_time_s"] = float(time_s[-1]) if len(time_s) else np.nan
    out["heading_deg"] = heading.heading_deg
    out["speed_m_per_s"] = heading.speed_m_per_s
    out["turn_deg"] = heading.turn_deg
    for axis, angle in zip("xyz", heading.rotation_deg):
        out[f"rotation_{axis}_deg"] = angle
    return out


def _cropped(time_s, markers_m, span_s: Sequence[float], source: str):
    """Frames of a trial between ``span_s`` = (start, end) in s on the file's clock; an empty crop is refused."""
    start, end = (float(v) for v in span_s)
    keep = (time_s >= start - 1e-9) & (time_s <= end + 1e-9)
    if end <= start or not keep.any():
        raise LoperInputError(
            f"{source}: the trial's span {start:g} .. {end:g} s (markers.trial_spans_s) holds no frame of the file "
            f"({time_s[0]:.4f} .. {time_s[-1]:.4f} s)"
        )
    return time_s[keep], markers_m[keep]
