"""File steps of the subject's OpenSim model: the generic model, scaling to the static trial, the segment table.

:class:`ModelSettings` holds the model stage's settings of the config, built by :meth:`ModelSettings.from_config`;
:class:`ScaleFiles` the files of one scaling.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.io import scale_tool
from loper_analysis.io.atomic import PathLike, staged, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.segment_table import write_segments
from loper_analysis.motion.body_size import body_height_m, body_mass_kg, model_stature_m, require_stature
from loper_analysis.motion.marker_names import unknown_markers_hint
from loper_analysis.motion.markers import lab_up
from loper_analysis.motion.model_settings import STATIC_DURATION_S, STATIC_MAX_MOTION_RMS_M, ModelSettings
from loper_analysis.motion.plausibility import measurement_scale_factors, require_scale_factors
from loper_analysis.motion.scale_report import SCALE_FLOAT_FORMAT
from loper_analysis.swing_leg.dynamics import (
    BRACE_ATTACHMENT_FRACTION,
    SegmentParameters,
    segment_parameters_from_anthropometry,
)

__all__ = [
    "STATIC_DURATION_S",
    "STATIC_MAX_MOTION_RMS_M",
    "ModelSettings",
    "ScaleFiles",
    "generic_model",
    "scaled_model",
    "scale_with_setup",
    "scale",
    "segments_from_model_file",
    "anthropometric_segments",
]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ScaleFiles:
    """The files of scaling a generic model to a static trial.

    Attributes
    ----------
    generic_osim : path
        The generic ``.osim`` model.
    static_trc : path
        The static trial (``.trc``, any length unit OpenSim knows).
    out_osim : path
        The scaled model (written atomically).
    setup_xml : path, optional
        A lab's OpenSim ScaleTool setup (:func:`scale_with_setup`); None: the generated model's marker-pair
        measurements (:func:`scaled_model`).
    static_c3d : path, optional
        The static trial's C3D, whose force plates give the mass when none is given
        (:func:`loper_analysis.motion.static_trial.standing_mass_kg`).
    report_out : path, optional
        The scale report (TSV, :func:`loper_analysis.motion.scale_report.scale_report`).
    static_lab_angles : path, optional
        The lab's own joint angles of the static trial (TSV written by the markers step), for the report.
    """

    generic_osim: PathLike
    static_trc: PathLike
    out_osim: PathLike
    setup_xml: PathLike | None = None
    static_c3d: PathLike | None = None
    report_out: PathLike | None = None
    static_lab_angles: PathLike | None = None


def generic_model(
    out_osim: PathLike,
    height_m: float,
    mass_kg: float | None,
    static_c3d: PathLike | None = None,
    settings: ModelSettings = ModelSettings(),
) -> None:
    """The generic lower-body model (:func:`loper_analysis.motion.model.build_lower_body_model`) for this subject.

    Without ``mass_kg`` the mass comes from the force plates the subject
    stands on in the static trial ``static_c3d``, over its first
    ``settings.static_duration_s`` seconds (None: all of it; ``settings.rotation_deg`` tells the lab's
    vertical: :func:`loper_analysis.motion.static_trial.standing_mass_kg`).
    """
    from loper_analysis.io.osim import write_model
    from loper_analysis.motion.model import build_lower_body_model

    if mass_kg is None and static_c3d is not None:
        from loper_analysis.motion.static_trial import scale_window_s

        rec, plates = _static_record(static_c3d)
        window = scale_window_s(rec.time_s, (), settings.static_duration_s, source=str(static_c3d))
        mass_kg, source = body_mass_kg(None, rec, plates, window, lab_up(settings.rotation_deg))
        log.info("mass %.2f kg from the %s", mass_kg, source)
    mass_kg, _ = body_mass_kg(mass_kg)
    write_model(build_lower_body_model(height_m, mass_kg), out_osim)
    log.info("generic model for %s m, %s kg: %s", height_m, mass_kg, out_osim)


def scaled_model(
    files: ScaleFiles,
    mass_kg: float | None,
    settings: ModelSettings = ModelSettings(),
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> None:
    """Personalise the generated model with OpenSim's ScaleTool from a static trial (TRC).

    Each body is scaled uniformly by the ratio of the marker-pair distances in
    the static trial to those of the model
    (:data:`loper_analysis.motion.model.SCALE_MEASUREMENTS`); the mass distribution
    is preserved at ``mass_kg``. The files (but ``files.setup_xml``, which is not read), the window, the static
    pose, ``height_m`` and ``lab_labels`` are those of :func:`scale_with_setup`; every factor
    must lie in ``settings.factor_range`` (a factor near 10 or 1000 means markers in
    another unit than the TRC declares); nothing is written otherwise.
    """
    from loper_analysis.io.osim import read_model
    from loper_analysis.motion.marker_templates import measured_scale_tool
    from loper_analysis.motion.model import SCALE_MEASUREMENTS

    tool = measured_scale_tool({body: (pairs, [body]) for body, pairs in SCALE_MEASUREMENTS.items()})
    tool.getMarkerPlacer().setApply(False)
    generic_osim = Path(files.generic_osim)
    if not generic_osim.is_file():
        raise LoperInputError(f"file not found: {generic_osim}")
    generated = dataclasses.replace(files, setup_xml=None)
    _run_scale_tool(tool, read_model(generic_osim), generated, None, mass_kg, settings, height_m, lab_labels)


def scale(
    files: ScaleFiles,
    mass_kg: float | None,
    settings: ModelSettings = ModelSettings(),
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | PathLike | None = None,
) -> None:
    """The subject's scaled model: with a lab's ScaleTool setup (:func:`scale_with_setup`) when
    ``files.setup_xml`` is given, else with the generated model's marker-pair measurements (:func:`scaled_model`,
    which checks no ``settings.segment_bodies``); scale factors outside ``settings.factor_range`` are refused.
    ``lab_labels`` may be the static trial's markers summary (TSV with the columns ``label`` and ``marker``,
    written by the ``markers`` step)."""
    if isinstance(lab_labels, (str, Path)):
        lab_labels = _lab_labels(lab_labels)
    if files.setup_xml is None:
        generated = dataclasses.replace(settings, segment_bodies=None)
        scaled_model(files, mass_kg, generated, height_m, lab_labels)
    else:
        scale_with_setup(files, mass_kg, settings, height_m, lab_labels)


def segments_from_model_file(
    model_osim: PathLike,
    out_tsv: PathLike,
    settings: ModelSettings = ModelSettings(),
) -> SegmentParameters:
    """Segment table (TSV) of one leg of an OpenSim model file
    (:func:`loper_analysis.motion.segments.segments_from_model`).

    Parameters
    ----------
    model_osim : path
        A (scaled) ``.osim`` model: gait2392, Rajagopal2016, our generated
        model or any model whose bodies ``settings.segment_bodies`` names.
    out_tsv : path
        The table (:func:`loper_analysis.io.segment_table.write_segments`), written atomically.
    settings : ModelSettings
        ``side`` (the swing leg, ``"left"`` or ``"right"``), ``segment_bodies`` (segment -> body names with
        ``{s}`` for the side suffix, setting ``opensim.segment_bodies``; ``None``: the model's own kind) and
        ``attachment_fraction`` (rod attachment as a fraction of the thigh length, for a model without brace
        markers).

    Raises
    ------
    LoperInputError
        Missing or unreadable model, unknown side, a configured body missing.
    """
    from loper_analysis.checks import side as check_side
    from loper_analysis.constants import SIDE_SUFFIX
    from loper_analysis.io.osim import read_model
    from loper_analysis.motion.segments import segments_from_model

    side = settings.side
    check_side(side, str(model_osim))
    params = segments_from_model(
        read_model(model_osim),
        SIDE_SUFFIX[side],
        settings.segment_bodies,
        settings.attachment_fraction,
        source=str(model_osim),
    )
    write_segments(params, out_tsv)
    log.info("segment table of %s (%s leg)", model_osim, side)
    return params


def anthropometric_segments(
    out_tsv: PathLike, height_m: float, mass_kg: float, attachment_fraction: float = BRACE_ATTACHMENT_FRACTION
) -> SegmentParameters:
    """Segment table from height and mass with Winter's table (the command line's ``segments --height-m``)."""
    params = segment_parameters_from_anthropometry(height_m, mass_kg, attachment_fraction)
    write_segments(params, out_tsv)
    log.info("segment table for %s m, %s kg: %s", height_m, mass_kg, params)
    return params


def scale_with_setup(
    files: ScaleFiles,
    mass_kg: float | None,
    settings: ModelSettings = ModelSettings(),
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> None:
    """Scale a generic OpenSim model with a lab's own ScaleTool setup and a static trial (TRC).

    The setup (``opensim.ScaleTool(files.setup_xml)``) keeps its measurements,
    scale set, scaling order, mass-distribution flag, marker-placer tasks,
    time ranges and its marker set file (resolved, like OpenSim does,
    relative to the setup's folder); replaced are the generic model file,
    the marker file of the model scaler and the marker placer, the subject
    mass and the output files: only the final model is written, atomically,
    to ``files.out_osim`` (the marker placer's model when it applies, else the
    model scaler's).

    The static trial is averaged over a window
    (:func:`loper_analysis.motion.static_trial.scale_window_s`): ``settings.time_range_s``
    when given, else the setup's time ranges where they are set, else the
    first ``settings.static_duration_s`` seconds (None: the whole
    trial). Within it each marker counts where it is present: ScaleTool gets
    the window with every marker's missing frames holding its mean over the
    present ones (:func:`loper_analysis.motion.static_trial.static_pose`).

    Parameters
    ----------
    files : ScaleFiles
        The generic model, the static trial (``.trc``) and the scaled model;
        the ScaleTool setup (required here); optionally the static trial's C3D
        (the mass from its force plates) and the scale report
        (:func:`scale_report`).
    mass_kg : float or None
        Subject mass, kg (0 .. 300); None: from the force plates of
        ``files.static_c3d`` (seen along the vertical of ``settings.rotation_deg``:
        :func:`loper_analysis.motion.static_trial.standing_mass_kg`).
    settings : ModelSettings
        The window (``time_range_s``, ``static_duration_s``), the static trial's largest marker motion
        (``max_motion_rms_m``), the bodies the scaled model must have (``segment_bodies``), the plausible
        measurement factors (``factor_range``,
        :func:`loper_analysis.motion.plausibility.measurement_scale_factors`) and the lab's vertical.
    height_m : float, optional
        The subject's height (m) in the scale report; None: estimated from the scaled model.
    lab_labels : mapping, optional
        {model marker: lab label}, for messages and the report.

    Raises
    ------
    LoperInputError
        No setup in ``files``; a missing file; a file that is not a ScaleTool setup; measurement
        markers that the model (with the setup's marker set) or the static
        trial lacks (all listed); a measurement marker absent from every
        frame of the window (naming its lab label, the file and the window);
        a window outside the trial; a scaled model without the configured
        bodies; a measurement's scale factor outside ``settings.factor_range``
        (markers in another unit than the TRC declares); no mass; ScaleTool
        failing. Nothing is written then.
    """
    from loper_analysis.io.osim import read_marker_set, read_model, read_scale_setup

    if files.setup_xml is None:
        raise LoperInputError(f"{files.static_trc}: scaling with a lab's setup needs a ScaleTool setup, got none")
    generic_osim, setup_xml, static_trc = Path(files.generic_osim), Path(files.setup_xml), Path(files.static_trc)
    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if static_trc.suffix.lower() != ".trc":
        raise LoperInputError(f"{static_trc}: ScaleTool reads a static trial as .trc, got '{static_trc.suffix}'")
    tool = read_scale_setup(setup_xml)
    maker = tool.getGenericModelMaker()
    marker_set = scale_tool.setup_file(maker.getMarkerSetFileName(), setup_xml)
    if marker_set is not None and not marker_set.is_file():
        raise LoperInputError(
            f"{setup_xml}: GenericModelMaker/marker_set_file {maker.getMarkerSetFileName()} "
            f"not found (looked for {marker_set})"
        )
    generic = read_model(generic_osim)
    if marker_set is not None:
        generic.updateMarkerSet(read_marker_set(marker_set))  # as ScaleTool does: the set's markers replace or add
    model_markers = set(scale_tool.object_names(generic.getMarkerSet()))
    lacking = sorted(scale_tool.measurement_markers(tool) - model_markers)
    if lacking:
        extra = f" with marker set {marker_set}" if marker_set is not None else ""
        raise LoperInputError(
            f"{setup_xml}: measurement marker(s) {lacking} are not on the model {generic_osim}{extra}"
        )
    _run_scale_tool(tool, generic, files, marker_set, mass_kg, settings, height_m, lab_labels)


def _scaling_pose(tool, generic, files: ScaleFiles, settings: ModelSettings, lab_labels: Mapping[str, str] | None):
    """The static trial's scaling window (s), the tool's own time ranges (None where unset, or all when
    ``settings.time_range_s`` overrides them), its measurements' marker pairs and the averaged pose
    (:func:`loper_analysis.motion.static_trial.static_pose`), each checked."""
    from loper_analysis.io.opensim_tables import read_markers
    from loper_analysis.motion.static_trial import log_static_pose, scale_window_s, static_pose, time_range_is_set

    static_trc = Path(files.static_trc)
    setup_xml = None if files.setup_xml is None else Path(files.setup_xml)
    time_range_s = settings.time_range_s
    if not static_trc.is_file():
        raise LoperInputError(f"file not found: {static_trc}")
    where = str(setup_xml) if setup_xml is not None else str(static_trc)
    times, X, labels = read_markers(static_trc)
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    ranges = {part: scale_tool.time_range(part) for part in (scaler, placer) if part.getApply()}
    ranges = {part: r if time_range_is_set(r) else None for part, r in ranges.items()}  # None where unset
    setting = f"time_range of {setup_xml}" if setup_xml is not None else "markers.static_duration_s"
    if time_range_s is not None:
        t0, t1 = map(float, time_range_s)
        if not (t0 <= t1 and t0 <= times[-1] + 1e-9 and t1 >= times[0] - 1e-9):
            raise LoperInputError(
                f"{static_trc}: time_range_s {time_range_s} lies outside the trial "
                f"({times[0]:.3f} .. {times[-1]:.3f} s) or is reversed"
            )
        window = scale_window_s(times, [(t0, t1)], source=str(static_trc), setting="the time range given")
        ranges = dict.fromkeys(ranges)
    else:
        window = scale_window_s(
            times, list(ranges.values()), settings.static_duration_s, source=str(static_trc), setting=setting
        )
    pairs = scale_tool.measurement_pairs(tool)
    needed = sorted({m for p in pairs.values() for pair in p for m in pair})
    lacking = [m for m in needed if m not in labels]
    if lacking:
        raise LoperInputError(
            f"{where}: measurement marker(s) {lacking} are not in the static trial {static_trc}"
            f"{unknown_markers_hint(labels, scale_tool.object_names(generic.getMarkerSet()), lab_labels)}"
        )
    pose = static_pose(
        times,
        X,
        labels,
        window_s=window,
        needed=needed,
        lab_labels=lab_labels,
        source=str(static_trc),
        setting=setting,
        max_motion_rms_m=settings.max_motion_rms_m,
    )
    log_static_pose(pose, str(static_trc), window)
    return window, ranges, pairs, pose


def _run_scale_tool(
    tool,
    generic,
    files: ScaleFiles,
    marker_set: Path | None,
    mass_kg: float | None,
    settings: ModelSettings,
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> None:
    """Window, static pose, checks and mass, then OpenSim's ScaleTool and the scale report
    (:func:`scale_with_setup`; ``files.setup_xml`` None: the tool as :func:`scaled_model` built it)."""
    import tempfile

    from loper_analysis.io.osim import read_model
    from loper_analysis.motion.segments import check_segment_bodies

    generic_osim, static_trc, out_osim = Path(files.generic_osim), Path(files.static_trc), files.out_osim
    setup_xml = None if files.setup_xml is None else Path(files.setup_xml)
    segment_bodies = settings.segment_bodies
    where = str(setup_xml) if setup_xml is not None else str(static_trc)
    placer = tool.getMarkerPlacer()
    window, ranges, pairs, pose = _scaling_pose(tool, generic, files, settings, lab_labels)
    factors = measurement_scale_factors(generic, pairs, pose.markers_m, pose.labels)
    require_scale_factors(factors, str(static_trc), settings.factor_range)
    gravity = float(np.linalg.norm(generic.getGravity().to_numpy()))
    rec, plates = _static_record(files.static_c3d) if mass_kg is None and files.static_c3d else (None, [])
    mass_kg, mass_source = body_mass_kg(mass_kg, rec, plates, window, lab_up(settings.rotation_deg), gravity)
    maker = tool.getGenericModelMaker()
    tool.setPathToSubject("")  # OpenSim prefixes the setup's folder to every file name; ours are absolute
    tool.setSubjectMass(mass_kg)
    maker.setModelFileName(str(generic_osim.resolve()))
    maker.setMarkerSetFileName(str(marker_set) if marker_set is not None else "Unassigned")
    if setup_xml is not None:
        coordinates = scale_tool.setup_file(placer.getCoordinateFileName(), setup_xml)
        placer.setCoordinateFileName(str(coordinates) if coordinates is not None else "Unassigned")
    with tempfile.TemporaryDirectory(prefix="loper-scale-") as tmp_dir:
        trc, window = _window_file(tool, pose, ranges, window, Path(tmp_dir), static_trc)
        scale_file, unplaced_file = Path(tmp_dir) / "scale_set.xml", Path(tmp_dir) / "scaled_unplaced.osim"
        with staged(out_osim, "OpenSim model") as tmp:
            _run_tool(tool, (tmp, scale_file, unplaced_file), (trc, static_trc, generic_osim), where)
            scaled = read_model(tmp)
            check_segment_bodies(scaled, segment_bodies, source=f"{out_osim} (scaled from {generic_osim})")
            stature = model_stature_m(scaled, segment_bodies)
            stored = _stored_values(files.static_c3d)
            height = body_height_m(height_m, stored[0], stature, stored[1])
            require_stature(height, stature, str(static_trc))
            if files.report_out is not None:
                unplaced = read_model(unplaced_file) if unplaced_file.is_file() else None
                if unplaced is None and placer.getApply():
                    unplaced = generic  # placement without scaling: the generic markers are the ones placed
                subject = (mass_kg, height[0], f"mass: {mass_source}; height: {height[1]}", stature)
                scaling = (scale_tool.read_scale_factors(scale_file), scale_tool.placer_tasks(placer))
                _write_scale_report((scaled, unplaced), pose, scaling, subject, files, window, settings, lab_labels)
    log.info(
        "scaled %s to %s (window %.4f .. %.4f s, %d frames, %g kg)",
        generic_osim,
        static_trc,
        *window,
        len(pose.time_s),
        mass_kg,
    )


def _window_file(tool, pose, ranges, window, tmp_dir: Path, static_trc: Path):
    """Write the scaling window's pose as the TRC the tool reads and point the model scaler and the marker placer
    at it, each over its own time range or the window; returns the TRC and the window (a snapshot static trial:
    its frame twice, a frame apart, as OpenSim averages over a span)."""
    from loper_analysis.io.opensim_tables import trc_data_rate_hz, write_trc
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    trc = tmp_dir / "static_window.trc"
    t, X = pose.time_s, pose.markers_m
    if t.size == 1:
        rate_hz = trc_data_rate_hz(static_trc) or 100.0
        t, X = np.array([t[0], t[0] + 1.0 / rate_hz]), np.repeat(X, 2, axis=0)
        window = (float(t[0]), float(t[1]))
    write_trc(trc, t, X, pose.labels)
    for part in (tool.getModelScaler(), tool.getMarkerPlacer()):
        part.setMarkerFileName(str(trc))
        own = ranges.get(part)
        part.setTimeRange(scale_tool.array_double(osim, own if own is not None else window))
    return trc, window


def _run_tool(tool, outputs: tuple[Path, Path, Path], inputs: tuple[Path, Path, Path], where: str) -> None:
    """Run OpenSim's ScaleTool writing the model, the scale set and the model before marker placement
    (``outputs``) from the window's TRC, the static trial and the generic model (``inputs``, named in messages)."""
    (model, scale_file, unplaced_file), (trc, static_trc, generic_osim) = outputs, inputs
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    scaler.setOutputScaleFileName(str(scale_file) if scaler.getApply() else "Unassigned")
    placer.setOutputMotionFileName("Unassigned")
    placer.setOutputMarkerFileName("Unassigned")
    if placer.getApply():  # the model scaler's model too: the static pose before marker placement
        placer.setOutputModelFileName(str(model))
        scaler.setOutputModelFileName(str(unplaced_file) if scaler.getApply() else "Unassigned")
    else:
        scaler.setOutputModelFileName(str(model))
        placer.setOutputModelFileName("Unassigned")
    try:
        tool.run()  # False when the marker placer is off, even after a good scaling: the file tells
    except Exception as exc:  # OpenSim raises its own exception types
        said = str(exc).replace(str(trc), f"{static_trc} (the scaling window)")
        raise LoperInputError(
            f"{where}: OpenSim's ScaleTool failed for {static_trc} with {generic_osim} ({said})"
        ) from exc
    if not model.is_file():
        raise LoperInputError(
            f"{where}: OpenSim's ScaleTool wrote no model for {static_trc} with {generic_osim} (are the model "
            "scaler and the marker placer both off?)"
        )


def _write_scale_report(models, pose, scaling, subject, files: ScaleFiles, window, settings, lab_labels) -> None:
    """The scale report (:func:`loper_analysis.motion.scale_report.scaled_model_report`) of the scaled and the
    unplaced model, ``subject`` (mass kg, height m, their sources, the model's stature m), its warnings logged."""
    from loper_analysis.motion.scale_report import scaled_model_report

    lab_static = None if files.static_lab_angles is None else _lab_static(files.static_lab_angles, window)
    report = scaled_model_report(
        *models,
        pose,
        scaling,
        subject[:3],
        coordinate_map=settings.coordinate_map,
        accuracy=settings.accuracy,
        lab_labels=lab_labels,
        lab_static=lab_static,
        model_height_m=subject[3],
    )
    for text in report.loc[report["kind"] == "warning", "source"]:
        log.warning("%s: %s", files.static_trc, text)
    write_tsv(report, files.report_out, SCALE_FLOAT_FORMAT)
    log.info("scale report:\n%s", report.to_string(index=False))


def _lab_labels(summary_tsv: PathLike) -> dict[str, str]:
    """Model marker -> the lab's label, from the static trial's markers summary (columns ``label`` and ``marker``)."""
    table = read_tsv(summary_tsv, "markers summary", ("label", "marker"), dtype=str, keep_default_na=False)
    return dict(zip(table["marker"], table["label"]))


def _stored_values(static_c3d: PathLike | None) -> tuple[dict[str, float], str]:
    """The static trial's ``PROCESSING`` values (Nexus: ``Height`` mm) and its file name; empty without one."""
    from loper_analysis.io.c3d import read_c3d

    return ({}, "") if static_c3d is None else (read_c3d(static_c3d).processing, Path(static_c3d).name)


def _static_record(static_c3d: PathLike):
    """The static trial's recording and its force platforms (none when the file has none)."""
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.force_platforms import read_force_platforms

    rec = read_c3d(static_c3d)
    return rec, read_force_platforms(static_c3d) if rec.n_force_platforms else []


def _lab_static(lab_angles_tsv: PathLike, window: tuple[float, float]) -> dict[str, float]:
    """The lab's own joint angles of the static trial (rad), averaged over the scaling window
    (:func:`loper_analysis.motion.lab_angles.window_means`)."""
    from loper_analysis.motion.lab_angles import window_means

    return window_means(read_tsv(lab_angles_tsv, "lab angles", ("time_s",)), window)
