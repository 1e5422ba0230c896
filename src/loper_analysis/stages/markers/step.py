"""The ``markers`` step: a C3D's markers in the model's names and frame, gaps filled, low-passed, as a TRC.

:func:`markers` is the rule's and ``loper-analysis markers``' step; :class:`MarkerSettings` its settings,
built from the config by :mod:`loper_analysis.stages.markers.settings`.
"""

from __future__ import annotations

import logging

import pandas as pd

from loper_analysis.constants import MIN_IK_MARKERS
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_label_maps
from loper_analysis.motion.trial_markers import TRIAL_MARKER_COLUMNS, MarkerSettings, prepared_markers

__all__ = ["MarkerSettings", "TRIAL_MARKER_COLUMNS", "markers"]

log = logging.getLogger(__name__)


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
    frames on its own (:func:`loper_analysis.filtering.lowpass_finite_runs`).
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

    A trial whose pelvis rises or falls more than half a stair step, or whose force plates lie at different
    heights, is warned about as not level walking before its speed is given
    (:mod:`loper_analysis.motion.level_walking`); the summary's ``pelvis_height_change_m``,
    ``plate_height_range_m`` and ``warnings`` hold the figures and the warning.

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

    rec = read_c3d(c3d_path)
    corners = _plate_corners(rec, c3d_path)
    prepared = prepared_markers(rec, read_label_maps(settings.label_map), settings, str(c3d_path), corners)
    gaps, summary = prepared.gaps, prepared.summary
    write_trc(trc_out, prepared.time_s, prepared.markers_m, prepared.names, rate_hz=rec.point_rate_hz)
    if lab_angles_out is not None:
        _write_lab_angles(rec, lab_angles_out)
    if gaps_out is not None:
        write_tsv(gaps, gaps_out)
    if summary_out is not None:
        write_tsv(summary, summary_out)
    _log_missing(gaps, summary, str(c3d_path), len(prepared.time_s))
    gaps.attrs["per_marker"] = summary.to_dict("records")
    return gaps


def _plate_corners(rec, c3d_path: PathLike) -> list:
    """The corners of the file's force plates ((4, 3) each, m, lab frame); none without plates, or where the
    plates cannot be read (said in the log: the events and grf steps stop on them)."""
    from loper_analysis.errors import LoperInputError
    from loper_analysis.io.force_platforms import read_force_platforms

    if not rec.n_force_platforms:
        return []
    try:
        return [p.corners_m for p in read_force_platforms(c3d_path)]
    except LoperInputError as exc:
        log.info("%s: the force plates' heights are not compared: %s", c3d_path, exc)
        return []


def _write_lab_angles(rec, out: PathLike) -> None:
    """The lab's own joint angles of a recording (:func:`loper_analysis.motion.lab_angles.lab_joint_angles`)."""
    from loper_analysis.motion.lab_angles import lab_joint_angles

    table, used = lab_joint_angles(
        rec.time_s, rec.output_labels, rec.output_kinds, rec.outputs, rec.output_units.get("ANGLES"), rec.source
    )
    write_tsv(table if used else table.iloc[:0], out)  # no lab angles: the header alone, not a column of times
    if used:
        log.info("%s: the lab's own joint angles: %s", rec.source, ", ".join(f"{k} <- {v}" for k, v in used.items()))


def _log_missing(gaps: pd.DataFrame, summary: pd.DataFrame, source: str, n_frames: int) -> None:
    """Log the filled gaps, warn of markers still missing and of frames too sparse for IK."""
    log.info("filled gaps:\n%s", gaps.to_string(index=False))
    left = summary[summary.n_missing_frames > 0]
    if len(left):
        log.warning(
            "%s: %d marker(s) still missing in some frames (written as NaN):\n%s",
            source,
            len(left),
            left[["label", "marker", "n_missing_frames", "longest_gap_frames"]].to_string(index=False),
        )
    n_sparse = int(summary["n_frames_too_few_markers"].iloc[0]) if len(summary) else 0
    if n_sparse:
        log.warning(
            "%s: %d of %d frames hold fewer than %d markers (outside the capture volume?): IK leaves them out",
            source,
            n_sparse,
            n_frames,
            MIN_IK_MARKERS,
        )
