"""The ``markers`` step: a C3D's markers in the model's names and frame, gaps filled, low-passed, as a TRC.

:func:`markers` is the rule's and ``loper-analysis markers``' step; :class:`MarkerSettings` its settings,
built from the config by :meth:`MarkerSettings.from_config`.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG, MIN_IK_MARKERS
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_label_maps
from loper_analysis.motion.filtering import CUTOFF_HZ, ORDER
from loper_analysis.motion.heading import MIN_TRAVEL_SPEED_M_PER_S
from loper_analysis.motion.markers import MAX_GAP_FRAMES
from loper_analysis.motion.plausibility import EXTENT_RANGE_M

__all__ = ["MarkerSettings", "TRIAL_MARKER_COLUMNS", "markers"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class MarkerSettings:
    """How a trial's markers are named, cropped, filled, turned and filtered (config ``markers.*``, ``filter.*``).

    ``rotation_deg``: lab -> model rotation about the fixed X, Y, Z axes (degrees); ``walking_direction``:
    ``"auto"`` turns a travelling trial to walk along the model's +X, ``"fixed"`` keeps ``rotation_deg``;
    ``min_travel_speed_m_per_s``: the speed from which a trial travels (m/s); ``max_gap_frames``: interior gaps
    up to this many frames are filled (0: none); ``cutoff_hz``, ``order``: the zero-phase Butterworth low-pass
    (Hz; None or 0: none); ``extent_range_m``: the markers' largest distance (m) a file in the declared unit
    can have; ``label_map``: {lab label: model marker}, a file, or a sequence of them merged in order;
    ``span_s``: (start, end) on the file's clock (s) or None; ``duration_s``: keep the first seconds or None;
    ``required_markers``: model markers that must be found, or None.
    """

    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    walking_direction: str = "auto"
    min_travel_speed_m_per_s: float = MIN_TRAVEL_SPEED_M_PER_S
    max_gap_frames: int = MAX_GAP_FRAMES
    cutoff_hz: float | None = CUTOFF_HZ
    order: int = ORDER
    extent_range_m: tuple[float, float] = EXTENT_RANGE_M
    label_map: Mapping[str, str] | PathLike | Sequence | None = None
    span_s: tuple[float, float] | None = None
    duration_s: float | None = None
    required_markers: tuple[str, ...] | None = None

    @classmethod
    def from_config(cls, config: Mapping) -> MarkerSettings:
        """The walking trials' settings from a validated config (``markers.*``, ``filter.*``)."""
        m, f = config["markers"], config["filter"]
        return cls(
            rotation_deg=tuple(float(v) for v in m["lab_to_model_rotation_deg"]),
            walking_direction=m["walking_direction"],
            min_travel_speed_m_per_s=float(m["min_travel_speed_m_per_s"]),
            max_gap_frames=int(m["max_gap_frames"]),
            cutoff_hz=f["cutoff_hz"],
            order=int(f["order"]),
            extent_range_m=tuple(float(v) for v in m["extent_range_m"]),
        )

    def for_static(self) -> MarkerSettings:
        """The static trial's settings: neither filled nor filtered (scaling averages each marker over the frames
        it is present in, as OpenSim's ScaleTool reads a lab's static trial)."""
        return dataclasses.replace(self, max_gap_frames=0, cutoff_hz=None)


def markers(
    c3d_path: PathLike,
    trc_out: PathLike,
    gaps_out: PathLike | None = None,
    settings: MarkerSettings = MarkerSettings(),
    summary_out: PathLike | None = None,
    lab_angles_out: PathLike | None = None,
) -> pd.DataFrame:
    """C3D markers -> model names -> gap fill -> lab-to-model rotation -> zero-phase low-pass -> TRC (mm).

    The fields of ``settings`` (:class:`MarkerSettings`) name what follows. Labels lose their subject
    prefix (``Subject:LASI`` -> ``LASI``) and are
    renamed by ``label_map`` {lab label: model marker}, or by several maps
    merged in order (:func:`loper_analysis.motion.marker_names.model_marker_names`);
    every marker of ``required_markers`` must then be among them. Interior
    gaps of up to ``max_gap_frames`` frames are filled (0: none); longer gaps
    and gaps at the trial's ends stay NaN and are written to the TRC as
    missing. The low-pass (``cutoff_hz`` Hz, Butterworth of ``order`` run
    forward and backward; None or 0: no filter) runs over each run of present
    frames on its own (:func:`loper_analysis.motion.filtering.lowpass_finite_runs`).
    Times are the file's own, ``(first_frame + k) / rate``; ``duration_s``
    keeps the first ``duration_s`` seconds of the trial, ``span_s`` (start,
    end) the frames between two times of the file's clock (a crop set per
    trial). Markers whose spread lies outside ``extent_range_m`` (m) are
    refused as numbers in another unit than ``POINT:UNITS`` declares
    (:func:`loper_analysis.motion.plausibility.require_marker_extent`).

    ``walking_direction`` ``"auto"`` turns a trial that travels (overground)
    about the vertical so that it walks along the model's +X
    (:func:`loper_analysis.motion.heading.trial_heading`); ``"fixed"`` keeps
    ``rotation_deg``.

    A knee alignment device (``LKAX``, ``LKD1``, ``LKD2`` after the label map) in a trial without the knee
    marker (``LKNE``) yields that marker (:func:`loper_analysis.motion.knee_alignment.kad_knee_markers`).
    Points that are not markers (a lab's model outputs: :mod:`loper_analysis.io.c3d_points`) are left out;
    the lab's own sagittal joint angles among them are written to ``lab_angles_out`` when given (``time_s``
    on the file's clock and ``{angle}_rad``; the header ``time_s`` alone when the file holds none:
    :func:`loper_analysis.motion.lab_angles.lab_joint_angles`).

    Returns the table of filled gaps (written to ``gaps_out`` when given; one
    row per gap, :data:`loper_analysis.motion.markers.GAP_REPORT_COLUMNS`). The
    per-marker summary (:func:`loper_analysis.motion.markers.gap_summary`, with the
    lab ``label`` of each marker and the trial's frames with fewer than
    :data:`~loper_analysis.constants.MIN_IK_MARKERS` markers, its span,
    heading and rotation: :data:`TRIAL_MARKER_COLUMNS`) is written to
    ``summary_out`` when given and kept as a list of row dicts in
    ``.attrs["per_marker"]`` (plain values: pandas compares the attrs of frames
    it concatenates).
    """
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.opensim_tables import write_trc
    from loper_analysis.motion.filtering import lowpass_finite_runs
    from loper_analysis.motion.heading import trial_heading
    from loper_analysis.motion.knee_alignment import kad_knee_markers
    from loper_analysis.motion.label_matching import landmark_indices
    from loper_analysis.motion.marker_names import model_marker_names, require_model_markers
    from loper_analysis.motion.markers import fill_gaps, gap_summary, rotate_markers
    from loper_analysis.motion.plausibility import require_marker_extent

    s = settings
    source = str(c3d_path)
    rec = read_c3d(c3d_path)
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
    names = model_marker_names(rec.marker_labels, read_label_maps(s.label_map), source)
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
    pelvis = (landmark_indices(names, ["asis"]), landmark_indices(names, ["psis", "sacrum"]))
    heading = trial_heading(
        raw, rec.point_rate_hz, s.rotation_deg, s.walking_direction, s.min_travel_speed_m_per_s, source, pelvis
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
    filled, gaps = fill_gaps(raw, s.max_gap_frames, names, source=source, unfillable="keep")
    X = rotate_markers(filled, heading.rotation_deg)
    unfiltered = None
    if s.cutoff_hz:
        try:
            X, unfiltered = lowpass_finite_runs(
                X, rec.point_rate_hz, s.cutoff_hz, s.order, axis=0, setting="filter.cutoff_hz", rate_name="POINT:RATE"
            )
        except LoperInputError as exc:
            raise LoperInputError(f"{c3d_path}: markers: {exc}") from None
    summary = _trial_marker_summary(gap_summary(raw, X, names, unfiltered), labels, time_s, X, heading)
    log.info(
        "%s: %d frames at %g Hz, %d markers, %d gap(s) filled",
        c3d_path,
        len(time_s),
        rec.point_rate_hz,
        len(names),
        len(gaps),
    )
    write_trc(trc_out, time_s, X, names, rate_hz=rec.point_rate_hz)
    if lab_angles_out is not None:
        _write_lab_angles(rec, lab_angles_out)
    if gaps_out is not None:
        write_tsv(gaps, gaps_out)
    if summary_out is not None:
        write_tsv(summary, summary_out)
    log.info("filled gaps:\n%s", gaps.to_string(index=False))
    left = summary[summary.n_missing_frames > 0]
    if len(left):
        log.warning(
            "%s: %d marker(s) still missing in some frames (written as NaN):\n%s",
            c3d_path,
            len(left),
            left[["label", "marker", "n_missing_frames", "longest_gap_frames"]].to_string(index=False),
        )
    n_sparse = int(summary["n_frames_too_few_markers"].iloc[0]) if len(summary) else 0
    if n_sparse:
        log.warning(
            "%s: %d of %d frames hold fewer than %d markers (outside the capture volume?): IK leaves them out",
            c3d_path,
            n_sparse,
            len(time_s),
            MIN_IK_MARKERS,
        )
    gaps.attrs["per_marker"] = summary.to_dict("records")
    return gaps


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


def _write_lab_angles(rec, out: PathLike) -> None:
    """The lab's own joint angles of a recording (:func:`loper_analysis.motion.lab_angles.lab_joint_angles`)."""
    from loper_analysis.motion.lab_angles import lab_joint_angles

    table, used = lab_joint_angles(
        rec.time_s, rec.output_labels, rec.output_kinds, rec.outputs, rec.output_units.get("ANGLES"), rec.source
    )
    write_tsv(table if used else table.iloc[:0], out)  # no lab angles: the header alone, not a column of times
    if used:
        log.info("%s: the lab's own joint angles: %s", rec.source, ", ".join(f"{k} <- {v}" for k, v in used.items()))


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
