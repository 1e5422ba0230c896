"""File steps of the subject's OpenSim model: the generic model, scaling to the static trial, the segment table.

:class:`ModelSettings` holds the model stage's settings of the config, built by
:mod:`loper_analysis.stages.model.settings`;
:class:`ScaleFiles` the files of one scaling.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io import scale_tool
from loper_analysis.io.atomic import PathLike, write_bytes, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.io.segment_table import write_segments
from loper_analysis.motion.body_size import body_mass_kg
from loper_analysis.motion.markers import lab_up
from loper_analysis.motion.model_settings import STATIC_DURATION_S, STATIC_MAX_MOTION_RMS_M, ModelSettings
from loper_analysis.motion.scale_report import SCALE_FLOAT_FORMAT, joint_centre_rows, scale_run_report
from loper_analysis.motion.scaling import (
    generated_scale_tool,
    scaled_subject,
    scaling_mass_kg,
    scaling_pose,
    with_joint_centres,
)
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
        measurements (:func:`scale`).
    static_c3d : path, optional
        The static trial's C3D, whose force plates give the mass when none is given
        (:func:`loper_analysis.motion.body_size.standing_mass_kg`).
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
    stands on in the static trial ``static_c3d``, over its stillest
    ``settings.static_duration_s`` seconds (None: all of it; ``settings.rotation_deg`` tells the lab's
    vertical: :func:`loper_analysis.motion.body_size.standing_mass_kg`).
    """
    from loper_analysis.io.osim import write_model
    from loper_analysis.motion.model import build_lower_body_model

    if mass_kg is None and static_c3d is not None:
        from loper_analysis.motion.static_trial import scale_window_s

        rec, plates = _static_record(static_c3d)
        window = scale_window_s(
            rec.time_s,
            (),
            settings.static_duration_s,
            str(static_c3d),
            markers_m=rec.markers_m,
            labels=rec.marker_labels,
        )
        mass_kg, source = body_mass_kg(None, rec, plates, window, lab_up(settings.rotation_deg))
        log.info("mass %.2f kg from the %s", mass_kg, source)
    mass_kg, _ = body_mass_kg(mass_kg)
    write_model(build_lower_body_model(height_m, mass_kg), out_osim)
    log.info("generic model for %s m, %s kg: %s", height_m, mass_kg, out_osim)


def scale(
    files: ScaleFiles,
    mass_kg: float | None,
    settings: ModelSettings = ModelSettings(),
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | PathLike | None = None,
) -> None:
    """The subject's scaled model: with a lab's ScaleTool setup (:func:`scale_with_setup`) when
    ``files.setup_xml`` is given, else the generated model personalised with OpenSim's ScaleTool.

    The generated model's bodies are each scaled uniformly by the ratio of the marker-pair distances in the
    static trial to those of the model (:data:`loper_analysis.motion.model.SCALE_MEASUREMENTS`,
    :func:`loper_analysis.motion.scaling.generated_scale_tool`), the mass distribution preserved at ``mass_kg``,
    checking no ``settings.segment_bodies``; the window, the static pose, ``height_m`` and ``lab_labels`` are
    those of :func:`scale_with_setup`. Every scale factor must lie in ``settings.factor_range`` (a factor near 10
    or 1000 means markers in another unit than the TRC declares); nothing is written otherwise.
    ``lab_labels`` may be the static trial's markers summary (TSV with the columns ``label`` and ``marker``,
    written by the ``markers`` step)."""
    from loper_analysis.io.osim import read_model

    if isinstance(lab_labels, (str, Path)):
        lab_labels = _lab_labels(lab_labels)
    if files.setup_xml is not None:
        scale_with_setup(files, mass_kg, settings, height_m, lab_labels)
        return
    generic_osim = Path(files.generic_osim)
    if not generic_osim.is_file():
        raise LoperInputError(f"file not found: {generic_osim}")
    generated = dataclasses.replace(settings, segment_bodies=None)
    _scale(generated_scale_tool(), read_model(generic_osim), files, None, mass_kg, generated, height_m, lab_labels)


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
        ``{s}`` for the side suffix, setting ``model.segment_bodies``; ``None``: the model's own kind) and
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
    stillest ``settings.static_duration_s`` seconds (None: the whole
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
        :func:`loper_analysis.motion.body_size.standing_mass_kg`).
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
    if files.setup_xml is None:
        raise LoperInputError(f"{files.static_trc}: scaling with a lab's setup needs a ScaleTool setup, got none")
    tool, generic, marker_set = scale_tool.read_setup_tool(
        Path(files.setup_xml), Path(files.generic_osim), Path(files.static_trc)
    )
    _scale(tool, generic, files, marker_set, mass_kg, settings, height_m, lab_labels)


def _scale(
    tool,
    generic,
    files: ScaleFiles,
    marker_set: Path | None,
    mass_kg: float | None,
    settings: ModelSettings,
    height_m: float | None = None,
    lab_labels: Mapping[str, str] | None = None,
) -> None:
    """Read the static trial, run OpenSim's ScaleTool on its scaling window, write the scale report and the model
    (:func:`scale_with_setup`; ``files.setup_xml`` None: the generated model's ``tool``, :func:`scale`)."""
    from loper_analysis.io.opensim_tables import read_markers

    generic_osim, static_trc, out_osim = Path(files.generic_osim), Path(files.static_trc), files.out_osim
    setup_xml = None if files.setup_xml is None else Path(files.setup_xml)
    if not static_trc.is_file():
        raise LoperInputError(f"file not found: {static_trc}")
    markers, centre_methods = _with_joint_centres(read_markers(static_trc), generic, files.static_c3d, static_trc)
    static = scaling_pose(
        tool,
        generic,
        markers,
        settings,
        static_trc=str(static_trc),
        setup_xml=None if setup_xml is None else str(setup_xml),
        lab_labels=lab_labels,
    )
    rec, plates = _static_record(files.static_c3d) if mass_kg is None and files.static_c3d else (None, [])
    mass = scaling_mass_kg(generic, mass_kg, rec, plates, static.window_s, settings)
    run = scale_tool.run_scale_tool(
        tool,
        static.pose,
        static.window_s,
        static.ranges,
        mass_kg=mass[0],
        generic_osim=generic_osim,
        static_trc=static_trc,
        out_name=Path(out_osim).name,
        marker_set=marker_set,
        setup_xml=setup_xml,
    )
    subject = scaled_subject(
        run.scaled,
        mass,
        settings,
        height_m,
        _stored_values(files.static_c3d),
        model_source=f"{out_osim} (scaled from {generic_osim})",
        static_trc=str(static_trc),
    )
    if files.report_out is not None:
        lab_angles = None if files.static_lab_angles is None else _lab_angles(files.static_lab_angles)
        report = scale_run_report(
            run,
            generic,
            static.pose,
            subject,
            settings,
            lab_labels=lab_labels,
            lab_angles=lab_angles,
            between_centres=_between_centres(tool, centre_methods),
        )
        report = joint_centre_rows(report, centre_methods)
        _write_scale_report(report, files)
    write_bytes(out_osim, run.model_osim, "OpenSim model")
    log.info(
        "scaled %s to %s (window %.4f .. %.4f s, %d frames, %g kg)",
        generic_osim,
        static_trc,
        *run.window_s,
        len(static.pose.time_s),
        mass[0],
    )


def _with_joint_centres(markers, generic, static_c3d: PathLike | None, static_trc: Path):
    """The static trial with the joint centres the generic model's marker set holds (a template's:
    :func:`loper_analysis.motion.centre_markers.marker_set_centres`), computed with the widths the static C3D
    stores; unchanged (and no methods) for any other marker set."""
    from loper_analysis.motion.centre_markers import marker_set_centres
    from loper_analysis.motion.joint_centres import widths_from_processing
    from loper_analysis.stages.templates import read_templates

    names = scale_tool.object_names(generic.getMarkerSet())
    spec = marker_set_centres([t.joint_centres for t in read_templates().values()], names)
    if spec is None:
        return markers, {}
    widths = widths_from_processing(_stored_values(static_c3d)[0])
    markers, methods = with_joint_centres(markers, spec, widths, static_trc=str(static_trc))
    for name, how in methods.items():
        log.info("%s: joint centre %s: %s", static_trc, name, how)
    return markers, methods


def _between_centres(tool, centre_methods) -> set[str]:
    """The bodies the tool scales by measurements between joint centres only."""
    pairs, bodies = scale_tool.measurement_pairs(tool), scale_tool.measurement_bodies(tool)
    return {
        body
        for name, measured in pairs.items()
        if measured and all(a in centre_methods and b in centre_methods for a, b in measured)
        for body in bodies.get(name, [])
    }


def _write_scale_report(report, files: ScaleFiles) -> None:
    """Write the scale report (:func:`loper_analysis.motion.scale_report.scale_run_report`), its warnings logged."""
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


def _lab_angles(lab_angles_tsv: PathLike):
    """The lab's own joint angles of the static trial (TSV written by the markers step: ``time_s``, ``*_rad``)."""
    return read_tsv(lab_angles_tsv, "lab angles", ("time_s",))
