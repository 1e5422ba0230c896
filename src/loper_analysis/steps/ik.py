"""File steps of inverse kinematics: OpenSim IK of a trial's TRC to a .mot and the joint-angle table."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import LoperInputError
from ..io.atomic import PathLike, write_tsv

__all__ = ["ik_chunk", "ik_file", "ik_join", "ik_trial"]

log = logging.getLogger(__name__)


def _checked(res, source: str, max_marker_rms_m: float, max_rms_fraction: float):
    """Refuse a poor fit (:func:`loper_analysis.plausibility.require_ik_fit`); warn about coordinates left NaN."""
    from ..plausibility import require_ik_fit

    require_ik_fit(res.marker_rms_m, source, max_marker_rms_m, max_rms_fraction)
    if res.undetermined:
        log.warning("%s: no weighted marker present determines %s; written as NaN there", source,
                    ", ".join(f"{c} ({n} of {len(res.time_s)} frames)" for c, n in res.undetermined.items()))
    return res


def _solve(model_osim: PathLike, time_s: np.ndarray, markers_m: np.ndarray, labels: Sequence[str], tasks_file=None,
           default_weight: float = 1.0, marker_weights=None, coordinate_tasks=None, accuracy: float = 1e-6,
           source: str = "", min_markers: int = 3):
    """IK of marker arrays with the tasks of a file or of the config; returns the :class:`IKResult`."""
    from ..io.ik_tasks import read_ik_tasks
    from ..io.osim import read_model
    from ..kinematics import ik_task_weights, inverse_kinematics

    model = read_model(model_osim)
    tasks = read_ik_tasks(tasks_file) if tasks_file else None
    weights, coords = ik_task_weights(model, labels, tasks, default_weight, marker_weights, coordinate_tasks, source)
    return inverse_kinematics(model, time_s, markers_m, labels, weights, coords, accuracy=accuracy,
                              min_markers=min_markers, source=source)


def ik_chunk(model_osim: PathLike, trc_path: PathLike, out_mot: PathLike, chunk: int, n_chunks: int, tasks_file=None,
             default_weight: float = 1.0, marker_weights: Mapping[str, float] | None = None,
             coordinate_tasks: Mapping[str, Mapping] | None = None, accuracy: float = 1e-6,
             min_markers: int = 3, max_marker_rms_m: float = 0.02, max_rms_fraction: float = 0.1) -> pd.DataFrame:
    """IK of time chunk ``chunk`` of ``n_chunks`` of a TRC; writes a .mot (degrees), returns the coordinates.

    Markers missing (NaN) in a frame are left out of its solve; a frame with
    fewer than ``min_markers`` weighted markers stops the run with an error
    naming the frames and the TRC (:func:`loper_analysis.markers.require_markers_per_frame`).
    A marker RMS error above ``max_marker_rms_m`` (m) in more than
    ``max_rms_fraction`` of the frames stops it too, writing nothing
    (:func:`loper_analysis.plausibility.require_ik_fit`). Coordinates no
    marker determines are written as NaN, with a warning naming them.
    """
    from ..io.opensim_tables import read_markers, write_mot
    from ..kinematics import chunk_frames

    time_s, X, labels = read_markers(trc_path)
    sel = chunk_frames(len(time_s), n_chunks, chunk)
    res = _solve(model_osim, time_s[sel], X[sel], labels, tasks_file, default_weight, marker_weights,
                 coordinate_tasks, accuracy, source=str(trc_path), min_markers=min_markers)
    _checked(res, str(trc_path), max_marker_rms_m, max_rms_fraction)
    log.info("%s chunk %d/%d: %d frames, marker RMS error mean %.2f mm, max %.2f mm", trc_path, chunk, n_chunks,
             len(res.time_s), 1e3 * np.nanmean(res.marker_rms_m), 1e3 * np.nanmax(res.marker_max_m))
    frame = res.frame()
    write_mot(out_mot, frame, in_degrees=True)
    return frame


def ik_trial(model_osim: PathLike, trc_path: PathLike, out_mot: PathLike, angles_tsv: PathLike,
             coordinate_map: Mapping | None = None, tasks_file=None, default_weight: float = 1.0,
             marker_weights=None, coordinate_tasks=None, accuracy: float = 1e-6,
             min_markers: int = 3, max_marker_rms_m: float = 0.02, max_rms_fraction: float = 0.1) -> pd.DataFrame:
    """IK of a whole TRC in one go: the .mot (degrees) and the tidy angle table that :func:`ik_join` gives."""
    from ..kinematics import joint_angle_table

    coords = ik_chunk(model_osim, trc_path, out_mot, 0, 1, tasks_file, default_weight, marker_weights,
                      coordinate_tasks, accuracy, min_markers, max_marker_rms_m, max_rms_fraction)
    angles = joint_angle_table(coords, coordinate_map, source=str(out_mot))
    write_tsv(angles, angles_tsv)
    log.info("%d frames, %s", len(angles), list(angles.columns))
    return angles


def ik_join(chunk_mots: Sequence[PathLike], out_mot: PathLike, angles_tsv: PathLike,
            coordinate_map: Mapping | None = None) -> pd.DataFrame:
    """Join IK chunks into one .mot and the tidy angle table (rad, m; :data:`kinematics.ANGLE_COLUMNS`)."""
    from ..io.opensim_tables import read_mot, write_mot
    from ..kinematics import join_chunks, joint_angle_table

    frames = [read_mot(p) for p in chunk_mots]
    coords = join_chunks(frames, [str(p) for p in chunk_mots])
    angles = joint_angle_table(coords, coordinate_map, source=str(chunk_mots[0]))
    write_mot(out_mot, coords, in_degrees=True)
    write_tsv(angles, angles_tsv)
    log.info("%d frames, %s", len(angles), list(angles.columns))
    return angles


def ik_file(model_osim: PathLike, markers_path: PathLike, out_mot: PathLike, tasks_file=None,
            start_s: float | None = None, end_s: float | None = None,
            rotate_deg: Sequence[float] | None = None, accuracy: float = 1e-6, min_markers: int = 3,
            max_marker_rms_m: float = 0.02, max_rms_fraction: float = 0.1,
            label_map: Mapping[str, str] | None = None):
    """IK of a .c3d or .trc marker file to a .mot (degrees), for the command line.

    Labels lose a subject prefix (``Subject:LASI`` -> ``LASI``) and are
    renamed by ``label_map`` {lab label: model marker}
    (:func:`loper_analysis.marker_names.model_marker_names`). ``rotate_deg`` turns the markers into the model frame (default -90 0 0
    for a C3D, Qualisys Z-up -> OpenSim Y-up; 0 0 0 for a TRC). Without a
    task file every model marker found in the file gets weight 1. A poor fit
    (marker RMS error above ``max_marker_rms_m`` m in more than
    ``max_rms_fraction`` of the frames) is refused and nothing is written;
    coordinates no marker determines are NaN, with a warning. Returns the
    :class:`~loper_analysis.kinematics.IKResult`.
    """
    from ..io.ik_tasks import read_ik_tasks
    from ..io.opensim_tables import read_markers, write_mot
    from ..io.osim import read_model
    from ..kinematics import inverse_kinematics
    from ..marker_names import model_marker_names
    from ..markers import rotate_markers

    markers_path = Path(markers_path)
    time_s, markers_m, labels = read_markers(markers_path)
    labels = model_marker_names(labels, label_map, str(markers_path))
    if rotate_deg is None:
        rotate_deg = (-90.0, 0.0, 0.0) if markers_path.suffix.lower() == ".c3d" else (0.0, 0.0, 0.0)
    markers_m = rotate_markers(markers_m, rotate_deg)
    start = time_s[0] if start_s is None else start_s
    end = time_s[-1] if end_s is None else end_s
    sel = (time_s >= start - 1e-9) & (time_s <= end + 1e-9)
    if not sel.any():
        raise LoperInputError(
            f"{markers_path}: no frame between --start {start} and --end {end} s "
            f"(the file spans {time_s[0]:.4f} .. {time_s[-1]:.4f} s)"
        )
    weights, coordinate_tasks = (None, None) if tasks_file is None else read_ik_tasks(tasks_file)
    if weights is not None and not weights:
        weights = None  # a task file with coordinate tasks only: every model marker in the file, weight 1
    model = read_model(model_osim)
    try:
        result = inverse_kinematics(model, time_s[sel], markers_m[sel], labels, weights,
                                    coordinate_tasks, accuracy=accuracy, min_markers=min_markers)
    except LoperInputError as exc:
        raise LoperInputError(f"{markers_path} with {model_osim}: {exc}") from None
    _checked(result, f"{markers_path} with {model_osim}", max_marker_rms_m, max_rms_fraction)
    write_mot(out_mot, result.frame(), in_degrees=True)
    return result
