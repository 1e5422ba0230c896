"""File steps of inverse kinematics: OpenSim IK of a trial's TRC to a .mot and the joint-angle table.

Their settings are :class:`loper_analysis.motion.ik_settings.IKSettings` (config ``opensim.*``);
:func:`ik_trial`, :func:`ik_chunk` and :func:`ik_join` are the rules' steps, :func:`ik_file` the command's.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.motion.plausibility import IK_WARN_RMS_M

__all__ = ["ik_chunk", "ik_file", "ik_join", "ik_trial"]

log = logging.getLogger(__name__)


def _checked(res, source: str, settings: IKSettings):
    """Refuse a fit that only a mistake explains (:func:`loper_analysis.motion.plausibility.require_ik_fit`, with the
    limits of ``settings``); warn about a poor fit, frames left out and coordinates left NaN. Returns the poor-fit
    warning (or None)."""
    from loper_analysis.motion.plausibility import require_ik_fit

    poor = require_ik_fit(
        res.marker_rms_m, source, settings.max_marker_rms_m, settings.max_rms_fraction, settings.warn_marker_rms_m
    )
    if poor:
        log.warning("%s", poor)
    res.warning = poor
    if res.fallback_reason:
        log.info("%s: solved with OpenSim's IK solver, %s", source, res.fallback_reason)
    if res.n_left_out:
        t = res.time_s[res.solved]
        log.warning(
            "%s: %d of %d frames hold too few markers for IK and are left out (NaN); solved %d frames "
            "between %.4f and %.4f s",
            source,
            res.n_left_out,
            len(res.time_s),
            len(t),
            t[0],
            t[-1],
        )
    if res.undetermined:
        log.warning(
            "%s: no weighted marker present determines %s; written as NaN there",
            source,
            ", ".join(f"{c} ({n} of {len(res.time_s)} frames)" for c, n in res.undetermined.items()),
        )
    return poor


def _geometry_checked(
    model,
    markers_m: np.ndarray,
    labels: Sequence[str],
    settings: IKSettings,
    source: str,
    static_trc: PathLike | None = None,
):
    """Compare the trial's distances between markers on one body with the same pairs in the subject's static
    trial (``static_trc``, its TRC in the model's names), or without one with the model's markers
    (:func:`loper_analysis.motion.marker_geometry.marker_geometry`): beyond ``settings.geometry_stop_change``
    the trial is refused as another subject's, beyond ``settings.geometry_warn_change`` warned about. Against
    the model, a model not scaled to the subject (``settings.subjects_model`` False) only warns, unless the
    distances differ by a factor beyond 1.5 (a unit). Returns the median change and the warning (or None)."""
    from loper_analysis.motion.marker_geometry import (
        geometry_change,
        geometry_message,
        geometry_ratio,
        marker_geometry,
        same_body_marker_pairs,
    )

    if static_trc is None:
        table = marker_geometry(same_body_marker_pairs(model, labels), markers_m, labels)
        name, reference, stops = None, "the model's markers", settings.subjects_model
    else:
        from loper_analysis.io.opensim_tables import read_markers

        _, static_m, static_labels = read_markers(static_trc)
        pairs = same_body_marker_pairs(model, labels, min_distance_m=0.0)
        table = marker_geometry(pairs, markers_m, labels, static_m, static_labels)
        name, reference, stops = str(static_trc), f"the static trial {static_trc}", True
        if not len(table):
            log.warning("%s: no pair of markers on one body is in both this trial and %s: not compared", source, name)
    change = geometry_change(table)
    log.info("marker geometry against %s: median change %.2f %% over %d pairs", reference, 100 * change, len(table))
    stops = stops or not 2 / 3 < geometry_ratio(table) < 3 / 2
    if change > settings.geometry_stop_change and stops:
        stop = geometry_message(table, settings.geometry_stop_change, "ik.geometry_stop_change", name)
        raise LoperInputError(f"{source}: {stop}")
    if change > settings.geometry_warn_change:
        warning = geometry_message(table, settings.geometry_warn_change, "ik.geometry_warn_change", name)
        log.warning("%s: %s", source, warning)
        return change, warning
    return change, None


def _solve(
    model_osim: PathLike,
    time_s: np.ndarray,
    markers_m: np.ndarray,
    labels: Sequence[str],
    settings: IKSettings,
    source: str = "",
    static_trc: PathLike | None = None,
):
    """IK of marker arrays with the tasks of ``settings`` (its task file or its weights), after the marker
    geometry's check against the static trial ``static_trc`` (or the model's markers, :func:`_geometry_checked`);
    returns the :class:`IKResult`."""
    from loper_analysis.io.ik_tasks import read_ik_tasks
    from loper_analysis.io.osim import read_model
    from loper_analysis.motion.coordinate_signs import require_map_signs
    from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP, ik_task_weights, inverse_kinematics

    s = settings
    model = read_model(model_osim)
    cmap = DEFAULT_COORDINATE_MAP if s.coordinate_map is None else s.coordinate_map
    require_map_signs(model, cmap, str(model_osim), "ik.coordinate_map")
    tasks = read_ik_tasks(s.tasks_file) if s.tasks_file else None
    weights, coords = ik_task_weights(
        model, labels, tasks, s.default_weight, s.marker_weights, s.coordinate_tasks, source
    )
    change, warning = _geometry_checked(model, markers_m, labels, s, source, static_trc)
    res = inverse_kinematics(
        model,
        time_s,
        markers_m,
        labels,
        marker_weights=weights,
        coordinate_tasks=coords,
        tree_step_tolerance=s.tree_step_tolerance,
        opensim_accuracy=s.opensim_accuracy,
        min_markers=s.min_markers,
        source=source,
        solver=s.solver,
    )
    res.geometry_change = change
    if warning:
        res.warnings.append(warning)
    return res


def ik_chunk(
    model_osim: PathLike,
    trc_path: PathLike,
    out_mot: PathLike,
    chunk: int,
    n_chunks: int,
    settings: IKSettings = IKSettings(),
    static_trc: PathLike | None = None,
):
    """IK of time chunk ``chunk`` of ``n_chunks`` of a TRC; writes a .mot (degrees), returns the :class:`IKResult`.

    First the distances between markers on one body (median over the chunk's frames) are compared with the
    same pairs in the subject's static trial ``static_trc`` (the markers step's TRC, in the model's names), or,
    without one, with the model's markers: a median change beyond ``settings.geometry_stop_change`` stops
    it as another subject's trial, naming both files and the pairs
    (:mod:`loper_analysis.motion.marker_geometry`).

    The tasks, the solvers' tolerances and the limits are those of ``settings`` (:class:`IKSettings`).
    Markers missing (NaN) in a frame are left out of its solve; a frame with
    fewer than ``min_markers`` weighted markers (or with markers on the pelvis
    only) is left out of IK: NaN in every coordinate, with a warning giving
    the count and the span solved. Only a chunk without any frame to solve
    stops, naming the frames and the TRC. A marker RMS error above
    ``max_marker_rms_m`` (m) in more than ``max_rms_fraction`` of the frames
    stops it too, writing nothing; above ``warn_marker_rms_m`` the fit is
    kept with a warning (:func:`loper_analysis.motion.plausibility.require_ik_fit`).
    Coordinates no marker determines are written as NaN, with a warning
    naming them.
    """
    from loper_analysis.io.opensim_tables import read_markers, write_mot
    from loper_analysis.motion.ik import chunk_frames

    time_s, X, labels = read_markers(trc_path)
    sel = chunk_frames(len(time_s), n_chunks, chunk)
    source = f"{trc_path} with {model_osim}"
    res = _solve(model_osim, time_s[sel], X[sel], labels, settings, source, static_trc)
    _checked(res, source, settings)
    log.info(
        "%s chunk %d/%d: %d frames (%d solved), marker RMS error mean %.2f mm, max %.2f mm",
        trc_path,
        chunk,
        n_chunks,
        len(res.time_s),
        len(res.time_s) - res.n_left_out,
        1e3 * np.nanmean(res.marker_rms_m),
        1e3 * np.nanmax(res.marker_max_m),
    )
    write_mot(out_mot, res.frame(), in_degrees=True)
    return res


def _angle_checks(res, angles: pd.DataFrame, source: str) -> None:
    """Warn about joint angles that look inverted (:func:`loper_analysis.motion.plausibility.inverted_knee_warnings`);
    the warnings go to the log and to ``res.warnings`` (the trial's IK summary)."""
    from loper_analysis.motion.plausibility import inverted_knee_warnings

    for warning in inverted_knee_warnings(angles):
        log.warning("%s: %s", source, warning)
        res.warnings.append(warning)


def _lab_agreement(angles: pd.DataFrame, lab_angles_tsv: PathLike, res, agreement_tsv: PathLike | None, source: str):
    """Our angles against the lab's own (:func:`loper_analysis.motion.lab_angles.lab_agreement`): the table written
    to ``agreement_tsv``, each joint beyond the limits warned about (log and ``res.warnings``)."""
    from loper_analysis.motion.lab_angles import lab_agreement

    table = lab_agreement(angles, read_tsv(lab_angles_tsv, "lab angles", ("time_s",)))
    for row in table[table["warning"] != ""].itertuples():
        text = f"{row.angle} against the lab's own angle: {row.warning}"
        log.warning("%s: %s", source, text)
        res.warnings.append(text)
    if len(table):
        log.info(
            "agreement with the lab's own angles (deg):\n%s",
            table.assign(
                rms_diff_deg=np.degrees(table["rms_diff_rad"]), mean_offset_deg=np.degrees(table["mean_offset_rad"])
            )[["angle", "n_frames", "r", "rms_diff_deg", "mean_offset_deg"]].to_string(index=False),
        )
    if agreement_tsv is not None:
        write_tsv(table, agreement_tsv)
    return table


def _angle_outputs(
    res,
    angles: pd.DataFrame,
    warn_rms_m: float,
    outputs: tuple[PathLike, PathLike | None, PathLike | None, PathLike | None],
    source: str,
) -> pd.DataFrame:
    """What :func:`ik_trial` and :func:`ik_join` end with: the angles checked (:func:`_angle_checks`), compared
    with the lab's own (:func:`_lab_agreement`), the one-row IK summary (marker RMS error above ``warn_rms_m``, m,
    counted as poorly fitted) and the angle table written.

    ``outputs`` are the angle table, the summary, the lab's own angles (read) and the agreement table (the last
    three None: not written, not compared). Returns ``angles``.
    """
    angles_tsv, summary_tsv, lab_angles_tsv, agreement_tsv = outputs
    _angle_checks(res, angles, source)
    if lab_angles_tsv is not None:
        _lab_agreement(angles, lab_angles_tsv, res, agreement_tsv, source)
    if summary_tsv is not None:
        write_tsv(res.summary(warn_rms_m), summary_tsv)
    write_tsv(angles, angles_tsv)
    log.info("%d frames, %s", len(angles), list(angles.columns))
    return angles


def ik_trial(
    model_osim: PathLike,
    trc_path: PathLike,
    out_mot: PathLike,
    angles_tsv: PathLike,
    settings: IKSettings = IKSettings(),
    summary_tsv: PathLike | None = None,
    lab_angles: tuple[PathLike, PathLike | None] | None = None,
    static_trc: PathLike | None = None,
) -> pd.DataFrame:
    """IK of a whole TRC in one go (:func:`ik_chunk` with ``settings`` and the static trial ``static_trc``):
    the .mot (degrees), the tidy angle table that :func:`ik_join` gives (``settings.coordinate_map``), and
    (``summary_tsv``) the one-row IK summary (:meth:`loper_analysis.motion.ik.IKResult.summary`, with the
    worst marker and the warnings).

    ``lab_angles``: ``(lab_angles_tsv, agreement_tsv)``, the lab's own joint angles of the trial (written by
    the markers step, :func:`loper_analysis.motion.lab_angles.lab_joint_angles`) and where the agreement goes:
    our angles are compared with them and the agreement per angle written to ``agreement_tsv`` (None: not
    written; :func:`loper_analysis.motion.lab_angles.lab_agreement`), each joint beyond the limits warned
    about. ``static_trc``: the subject's static trial (the markers step's TRC), the reference of the marker
    geometry's check (:func:`ik_chunk`); None: the model's markers.
    A knee that flexes negative is warned about
    (:func:`loper_analysis.motion.plausibility.inverted_knee_warnings`).
    """
    from loper_analysis.motion.ik import joint_angle_table

    res = ik_chunk(model_osim, trc_path, out_mot, 0, 1, settings, static_trc)
    angles = joint_angle_table(res.frame(), settings.coordinate_map, source=f"{out_mot} (model {model_osim})")
    warn = settings.warn_marker_rms_m
    outputs = (angles_tsv, summary_tsv, *(lab_angles or (None, None)))
    return _angle_outputs(res, angles, IK_WARN_RMS_M if warn is None else warn, outputs, str(trc_path))


def ik_join(
    chunk_mots: Sequence[PathLike],
    out_mot: PathLike,
    angles_tsv: PathLike,
    settings: IKSettings = IKSettings(),
    summary_tsv: PathLike | None = None,
    lab_angles: tuple[PathLike, PathLike | None] | None = None,
) -> pd.DataFrame:
    """Join IK chunks into one .mot and the tidy angle table (rad, m; :data:`kinematics.ANGLE_COLUMNS`; the
    coordinates of ``settings.coordinate_map``).

    ``summary_tsv``: the one-row IK summary of the joined trial (frames left
    out are those without any coordinate; the chunks keep no marker errors,
    so those columns are NaN). ``lab_angles`` as in :func:`ik_trial`.
    """
    from loper_analysis.io.opensim_tables import read_mot, write_mot
    from loper_analysis.motion.ik import IKResult, join_chunks, joint_angle_table

    frames = [read_mot(p) for p in chunk_mots]
    coords = join_chunks(frames, [str(p) for p in chunk_mots])
    angles = joint_angle_table(coords, settings.coordinate_map, source=str(chunk_mots[0]))
    values = coords.drop(columns="time_s").to_numpy(float)
    none = np.full(len(coords), np.nan)
    joined = IKResult(coords["time_s"].to_numpy(float), values, [], none, none, solved=np.isfinite(values).any(axis=1))
    outputs = (angles_tsv, summary_tsv, *(lab_angles or (None, None)))
    _angle_outputs(joined, angles, IK_WARN_RMS_M, outputs, str(out_mot))
    write_mot(out_mot, coords, in_degrees=True)
    return angles


def ik_file(
    model_osim: PathLike,
    markers_path: PathLike,
    out_mot: PathLike,
    settings: IKSettings = IKSettings(),
    span_s: Sequence[float | None] | None = None,
    rotate_deg: Sequence[float] | None = None,
    label_map: Mapping[str, str] | None = None,
    walking_direction: str = "fixed",
):
    """IK of a .c3d or .trc marker file to a .mot (degrees), for the command line.

    Labels lose a subject prefix (``Subject:LASI`` -> ``LASI``) and are
    renamed by ``label_map`` {lab label: model marker}
    (:func:`loper_analysis.motion.marker_names.model_marker_names`). ``rotate_deg`` turns the markers into the
    model frame
    (default -90 0 0 for a C3D, Qualisys Z-up -> OpenSim Y-up; 0 0 0 for a TRC). ``span_s`` (start, end), s on
    the file's clock, is the part solved (None, or None for either end: from the first or to the last frame).
    Of ``settings`` (:class:`IKSettings`) the task file, the tolerances, ``min_markers`` and the limits count:
    without a task file every model marker found in the file gets weight 1. Frames with
    too few markers are left out (NaN), with a warning. A fit that only a
    mistake explains (marker RMS error above ``max_marker_rms_m`` m in more
    than ``max_rms_fraction`` of the frames) is refused and nothing is
    written; above ``warn_marker_rms_m`` it is kept with a warning;
    coordinates no marker determines are NaN, with a warning.
    ``walking_direction`` ``"auto"`` turns a trial that travels about the
    vertical to walk along the model's +X
    (:func:`loper_analysis.motion.heading.trial_heading`). Returns the
    :class:`~loper_analysis.motion.ik.IKResult`, its ``warning`` the poor-fit
    text (or None).
    """
    from loper_analysis.io.ik_tasks import read_ik_tasks
    from loper_analysis.io.opensim_tables import read_markers, write_mot
    from loper_analysis.io.osim import read_model
    from loper_analysis.motion.ik import inverse_kinematics
    from loper_analysis.motion.marker_names import model_marker_names
    from loper_analysis.motion.markers import rotate_markers

    markers_path = Path(markers_path)
    time_s, markers_m, labels = read_markers(markers_path)
    labels = model_marker_names(labels, label_map, str(markers_path))
    if rotate_deg is None:
        rotate_deg = LAB_TO_MODEL_ROTATION_DEG if markers_path.suffix.lower() == ".c3d" else (0.0, 0.0, 0.0)
    if walking_direction != "fixed":
        from loper_analysis.motion.heading import trial_heading

        rate = 1.0 / float(np.median(np.diff(time_s))) if len(time_s) > 1 else 1.0
        rotate_deg = trial_heading(
            markers_m, rate, rotate_deg, walking_direction, source=str(markers_path)
        ).rotation_deg
    markers_m = rotate_markers(markers_m, rotate_deg)
    start_s, end_s = (None, None) if span_s is None else span_s
    start = time_s[0] if start_s is None else start_s
    end = time_s[-1] if end_s is None else end_s
    sel = (time_s >= start - 1e-9) & (time_s <= end + 1e-9)
    if not sel.any():
        raise LoperInputError(
            f"{markers_path}: no frame between --start {start} and --end {end} s "
            f"(the file spans {time_s[0]:.4f} .. {time_s[-1]:.4f} s)"
        )
    tasks_file = settings.tasks_file
    weights, coordinate_tasks = (None, None) if tasks_file is None else read_ik_tasks(tasks_file)
    if weights is not None and not weights:
        weights = None  # a task file with coordinate tasks only: every model marker in the file, weight 1
    model = read_model(model_osim)
    change, warning = _geometry_checked(model, markers_m[sel], labels, settings, f"{markers_path} with {model_osim}")
    try:
        result = inverse_kinematics(
            model,
            time_s[sel],
            markers_m[sel],
            labels,
            marker_weights=weights,
            coordinate_tasks=coordinate_tasks,
            tree_step_tolerance=settings.tree_step_tolerance,
            opensim_accuracy=settings.opensim_accuracy,
            min_markers=settings.min_markers,
            solver=settings.solver,
        )
    except LoperInputError as exc:
        raise LoperInputError(f"{markers_path} with {model_osim}: {exc}") from None
    result.geometry_change = change
    if warning:
        result.warnings.append(warning)
    _checked(result, f"{markers_path} with {model_osim}", settings)
    write_mot(out_mot, result.frame(), in_degrees=True)
    return result
