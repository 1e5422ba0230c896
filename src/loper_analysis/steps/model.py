"""File steps of the subject's OpenSim model: the generic model, scaling to the static trial, the segment table.

:class:`ModelSettings` holds the model stage's settings of the config, built by :meth:`ModelSettings.from_config`;
:class:`ScaleFiles` the files of one scaling.
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.constants import GRAVITY_M_PER_S2, LAB_TO_MODEL_ROTATION_DEG
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike, staged, write_tsv
from loper_analysis.io.readers import read_tsv
from loper_analysis.motion.ik import IK_ACCURACY
from loper_analysis.motion.plausibility import SCALE_FACTOR_RANGE
from loper_analysis.motion.scale_report import SCALE_FLOAT_FORMAT
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.swing_leg.dynamics import (
    BRACE_ATTACHMENT_FRACTION,
    SegmentParameters,
    segment_parameters_from_anthropometry,
    write_segments,
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

#: Scaling averages the first this many seconds of the static trial when the scale setup sets no time range (s;
#: config ``markers.static_duration_s``).
STATIC_DURATION_S: float = 1.0
#: A static-trial marker moving more than this over the scaling window stops scaling (m, RMS about its mean;
#: config ``markers.static_max_motion_rms_m``).
STATIC_MAX_MOTION_RMS_M: float = 0.05


@dataclass(frozen=True)
class ModelSettings:
    """How the subject's model is built, scaled and turned into a segment table (config ``markers.*``,
    ``opensim.*``, ``trials.perturbed_side``).

    Attributes
    ----------
    rotation_deg : (float, float, float)
        Lab -> model rotation about the fixed X, Y, Z axes, degrees: the lab's vertical, for the mass from the
        static trial's force plates (``markers.lab_to_model_rotation_deg``).
    static_duration_s : float or None
        Without a time range (``time_range_s``, the scale setup's): the first this many seconds of the static
        trial are averaged, s; None: the whole trial (``markers.static_duration_s``).
    max_motion_rms_m : float or None
        Largest RMS motion of a marker over the window, m: a subject who does not stand still is refused; None:
        not checked (``markers.static_max_motion_rms_m``).
    time_range_s : (float, float), optional
        The window, s, overriding the setup's time ranges and ``static_duration_s`` (no config key).
    factor_range : (float, float)
        Least and largest plausible factor of a measurement (``opensim.scale_factor_range``).
    segment_bodies : mapping, optional
        Segment -> body names with ``{s}`` for the side suffix (``opensim.segment_bodies``); None: the model's
        own kind.
    side : {"left", "right"}
        The leg of the segment table (``trials.perturbed_side``).
    attachment_fraction : float
        Rod attachment as a fraction of the thigh length, for a model without brace markers
        (``opensim.brace_attachment_fraction``).
    coordinate_map : mapping, optional
        Our angle -> model coordinate and sign, for the static pose of the scale report
        (``opensim.coordinate_map``); None: :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`.
    accuracy : float
        IK solver accuracy of the scale report's static pose (``opensim.accuracy``).
    """

    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    static_duration_s: float | None = STATIC_DURATION_S
    max_motion_rms_m: float | None = STATIC_MAX_MOTION_RMS_M
    time_range_s: tuple[float, float] | None = None
    factor_range: tuple[float, float] = SCALE_FACTOR_RANGE
    segment_bodies: Mapping[str, Sequence[str]] | None = None
    side: str = PERTURBED_SIDE
    attachment_fraction: float = BRACE_ATTACHMENT_FRACTION
    coordinate_map: Mapping[str, Mapping] | None = None
    accuracy: float = IK_ACCURACY

    @classmethod
    def from_config(cls, config: Mapping) -> ModelSettings:
        """The model settings of a validated config (``markers.*``, ``opensim.*``, ``trials.perturbed_side``)."""
        m, o = config["markers"], config["opensim"]
        return cls(
            rotation_deg=tuple(float(v) for v in m["lab_to_model_rotation_deg"]),
            static_duration_s=m["static_duration_s"],
            max_motion_rms_m=m["static_max_motion_rms_m"],
            factor_range=tuple(float(v) for v in o["scale_factor_range"]),
            segment_bodies=o["segment_bodies"],
            side=config["trials"]["perturbed_side"],
            attachment_fraction=o["brace_attachment_fraction"],
            coordinate_map=o["coordinate_map"],
            accuracy=o["accuracy"],
        )


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
        from loper_analysis.io.c3d import read_c3d
        from loper_analysis.motion.static_trial import scale_window_s

        window = scale_window_s(read_c3d(static_c3d).time_s, (), settings.static_duration_s, source=str(static_c3d))
        mass_kg, source = _subject_mass(None, static_c3d, window, settings.rotation_deg)
        log.info("mass %.2f kg from the %s", mass_kg, source)
    mass_kg, _ = _subject_mass(mass_kg, None, (0.0, 0.0), settings.rotation_deg)
    write_model(build_lower_body_model(height_m, mass_kg), out_osim)
    log.info("generic model for %s m, %s kg: %s", height_m, mass_kg, out_osim)


def _check_factors(model, measurements, pose, static_trc, factor_range) -> None:
    """Refuse scale factors outside ``factor_range``
    (:func:`loper_analysis.motion.plausibility.require_scale_factors`)."""
    from loper_analysis.motion.plausibility import measurement_scale_factors, require_scale_factors

    factors = measurement_scale_factors(model, measurements, pose.markers_m, pose.labels)
    require_scale_factors(factors, str(static_trc), factor_range)


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
        The table (:func:`loper_analysis.swing_leg.dynamics.write_segments`), written atomically.
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
    """Segment table from height and mass with Winter's table (the validation study's subject, the CLI)."""
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
        The window (``time_range_s``, ``static_duration_s``); ``max_motion_rms_m``
        (largest RMS motion of a marker over the window, m: a subject who does
        not stand still is refused; None: not checked); ``segment_bodies`` (the
        bodies the segment table will need: the scaled model must have them on
        both sides); ``factor_range`` (least and largest plausible factor of a
        measurement: static-trial marker distance over the model's at its
        default pose, averaged over the measurement's pairs,
        :func:`loper_analysis.motion.plausibility.measurement_scale_factors`);
        ``rotation_deg`` (the lab's vertical, for the mass).
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
    marker_set = _setup_file(maker.getMarkerSetFileName(), setup_xml)
    if marker_set is not None and not marker_set.is_file():
        raise LoperInputError(
            f"{setup_xml}: GenericModelMaker/marker_set_file {maker.getMarkerSetFileName()} "
            f"not found (looked for {marker_set})"
        )
    generic = read_model(generic_osim)
    if marker_set is not None:
        generic.updateMarkerSet(read_marker_set(marker_set))  # as ScaleTool does: the set's markers replace or add
    model_markers = set(_names(generic.getMarkerSet()))
    lacking = sorted(_measurement_markers(tool) - model_markers)
    if lacking:
        extra = f" with marker set {marker_set}" if marker_set is not None else ""
        raise LoperInputError(
            f"{setup_xml}: measurement marker(s) {lacking} are not on the model {generic_osim}{extra}"
        )
    _run_scale_tool(tool, generic, files, marker_set, mass_kg, settings, height_m, lab_labels)


def _unknown_markers_hint(
    labels: Sequence[str], model_markers: Sequence[str], lab_labels: Mapping[str, str] | None
) -> str:
    """The trial's markers the model does not have, as a hint at a label-map typo ('' when there are none)."""
    import difflib

    unknown = [m for m in labels if m not in set(model_markers)]
    if not unknown:
        return ""
    shown = []
    for m in unknown:
        label = (lab_labels or {}).get(m)
        close = difflib.get_close_matches(m, model_markers, n=1)
        shown.append(
            (f"'{label}' mapped to {m}" if label and label != m else f"'{m}'")
            + (f" (the model has {close[0]})" if close else "")
        )
    return (
        f"; the trial's marker(s) {', '.join(shown)} are not on the model: a typo in the label map "
        "(markers.label_map, markers.trial_label_maps)?"
    )


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

    from loper_analysis.io.opensim_tables import read_markers, trc_data_rate_hz, write_trc
    from loper_analysis.io.osim import quiet_opensim, read_model
    from loper_analysis.motion.scale_report import scaled_model_report
    from loper_analysis.motion.segments import check_segment_bodies
    from loper_analysis.motion.static_trial import scale_window_s, static_pose

    generic_osim, static_trc, out_osim = Path(files.generic_osim), Path(files.static_trc), files.out_osim
    setup_xml = None if files.setup_xml is None else Path(files.setup_xml)
    time_range_s, segment_bodies = settings.time_range_s, settings.segment_bodies
    if not static_trc.is_file():
        raise LoperInputError(f"file not found: {static_trc}")
    where = str(setup_xml) if setup_xml is not None else str(static_trc)
    times, X, labels = read_markers(static_trc)
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    ranges = {part: _range(part) for part in (scaler, placer) if part.getApply()}  # None where unset
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
    pairs = _measurement_pairs(tool)
    needed = sorted({m for p in pairs.values() for pair in p for m in pair})
    lacking = [m for m in needed if m not in labels]
    if lacking:
        raise LoperInputError(
            f"{where}: measurement marker(s) {lacking} are not in the static trial {static_trc}"
            f"{_unknown_markers_hint(labels, _names(generic.getMarkerSet()), lab_labels)}"
        )
    pose = static_pose(
        times,
        X,
        labels,
        window,
        needed,
        lab_labels,
        source=str(static_trc),
        setting=setting,
        max_motion_rms_m=settings.max_motion_rms_m,
    )
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
    _check_factors(generic, pairs, pose, static_trc, settings.factor_range)
    gravity = float(np.linalg.norm(generic.getGravity().to_numpy()))
    mass_kg, mass_source = _subject_mass(mass_kg, files.static_c3d, window, settings.rotation_deg, gravity)
    osim = quiet_opensim()
    maker = tool.getGenericModelMaker()
    tool.setPathToSubject("")  # OpenSim prefixes the setup's folder to every file name; ours are absolute
    tool.setSubjectMass(mass_kg)
    maker.setModelFileName(str(generic_osim.resolve()))
    maker.setMarkerSetFileName(str(marker_set) if marker_set is not None else "Unassigned")
    if setup_xml is not None:
        coordinates = _setup_file(placer.getCoordinateFileName(), setup_xml)
        placer.setCoordinateFileName(str(coordinates) if coordinates is not None else "Unassigned")
    with tempfile.TemporaryDirectory(prefix="loper-scale-") as tmp_dir:
        trc = Path(tmp_dir) / "static_window.trc"
        t, X = pose.time_s, pose.markers_m
        if t.size == 1:  # a snapshot static trial: OpenSim averages over a span of frames, so the frame twice
            rate_hz = trc_data_rate_hz(static_trc) or 100.0
            t, X = np.array([t[0], t[0] + 1.0 / rate_hz]), np.repeat(X, 2, axis=0)
            window = (float(t[0]), float(t[1]))
        write_trc(trc, t, X, pose.labels)
        scale_file = Path(tmp_dir) / "scale_set.xml"
        for part in (scaler, placer):
            part.setMarkerFileName(str(trc))
            own = ranges.get(part)
            part.setTimeRange(_array(osim, own if own is not None else window))
        scaler.setOutputScaleFileName(str(scale_file) if scaler.getApply() else "Unassigned")
        placer.setOutputMotionFileName("Unassigned")
        placer.setOutputMarkerFileName("Unassigned")
        unplaced_file = Path(tmp_dir) / "scaled_unplaced.osim"
        with staged(out_osim, "OpenSim model") as tmp:
            if placer.getApply():  # the model scaler's model too: the static pose before marker placement
                placer.setOutputModelFileName(str(tmp))
                scaler.setOutputModelFileName(str(unplaced_file) if scaler.getApply() else "Unassigned")
            else:
                scaler.setOutputModelFileName(str(tmp))
                placer.setOutputModelFileName("Unassigned")
            try:
                tool.run()  # False when the marker placer is off, even after a good scaling: the file tells
            except Exception as exc:  # OpenSim raises its own exception types
                said = str(exc).replace(str(trc), f"{static_trc} (the scaling window)")
                raise LoperInputError(
                    f"{where}: OpenSim's ScaleTool failed for {static_trc} with {generic_osim} ({said})"
                ) from exc
            if not tmp.is_file():
                raise LoperInputError(
                    f"{where}: OpenSim's ScaleTool wrote no model for {static_trc} with "
                    f"{generic_osim} (are the model scaler and the marker placer both off?)"
                )
            scaled = read_model(tmp)
            check_segment_bodies(scaled, segment_bodies, source=f"{out_osim} (scaled from {generic_osim})")
            height = _subject_height(height_m, files.static_c3d, scaled, segment_bodies)
            stature = _model_stature(scaled, segment_bodies)
            _require_stature(height, stature, static_trc)
            if files.report_out is not None:
                unplaced = read_model(unplaced_file) if unplaced_file.is_file() else None
                if unplaced is None and placer.getApply():
                    unplaced = generic  # placement without scaling: the generic markers are the ones placed
                subject = (mass_kg, height[0], f"mass: {mass_source}; height: {height[1]}")
                lab_static = None if files.static_lab_angles is None else _lab_static(files.static_lab_angles, window)
                report = scaled_model_report(
                    scaled,
                    unplaced,
                    pose,
                    (_scale_factors(scale_file), _placer_tasks(placer)),
                    subject,
                    coordinate_map=settings.coordinate_map,
                    accuracy=settings.accuracy,
                    lab_labels=lab_labels,
                    lab_static=lab_static,
                    model_height_m=stature,
                )
                for text in report.loc[report["kind"] == "warning", "source"]:
                    log.warning("%s: %s", static_trc, text)
                write_tsv(report, files.report_out, SCALE_FLOAT_FORMAT)
                log.info("scale report:\n%s", report.to_string(index=False))
    log.info(
        "scaled %s to %s (window %.4f .. %.4f s, %d frames, %g kg)",
        generic_osim,
        static_trc,
        *window,
        len(pose.time_s),
        mass_kg,
    )


def _lab_labels(summary_tsv: PathLike) -> dict[str, str]:
    """Model marker -> the lab's label, from the static trial's markers summary (columns ``label`` and ``marker``)."""
    table = read_tsv(summary_tsv, "markers summary", ("label", "marker"), dtype=str, keep_default_na=False)
    return dict(zip(table["marker"], table["label"]))


def _range(part) -> tuple[float, float] | None:
    """A model scaler's or marker placer's time range, None when unset (``-1 -1`` or reversed)."""
    from loper_analysis.motion.static_trial import time_range_is_set

    r = part.getTimeRange()
    pair = (r.get(0), r.get(1)) if r.getSize() >= 2 else None
    return pair if time_range_is_set(pair) else None


def _array(osim, pair) -> object:
    out = osim.ArrayDouble()
    for value in pair:
        out.append(float(value))
    return out


def _subject_mass(
    mass_kg: float | None,
    static_c3d: PathLike | None,
    window: tuple[float, float],
    rotation_deg: Sequence[float],
    gravity_m_per_s2: float = GRAVITY_M_PER_S2,
) -> tuple[float, str]:
    """The subject's mass (kg) and where it came from: given, or from the static trial's force plates (weight over
    the model's gravity)."""
    from loper_analysis.io.force_platforms import read_force_platforms
    from loper_analysis.motion.markers import lab_up
    from loper_analysis.motion.static_trial import standing_mass_kg

    if mass_kg is not None:
        if not 0 < mass_kg <= 300:
            raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
        return float(mass_kg), "given"
    if static_c3d is None:
        raise LoperInputError(
            "no body mass: give mass_kg (subject sheet), or a static trial that stands on force plates"
        )
    plates = read_force_platforms(static_c3d)
    if not plates:
        return _file_bodymass(static_c3d, "the static trial has no force platforms (FORCE_PLATFORM:USED 0)")
    up = lab_up(rotation_deg)
    vertical = np.column_stack([p.force_n @ up for p in plates])
    off = _feet_off_plates(static_c3d, plates, vertical, window, up)
    if off:
        return _file_bodymass(static_c3d, off)
    mass = standing_mass_kg(plates[0].time_s, vertical, window, gravity_m_per_s2, source=str(static_c3d))
    return mass, f"force plates {', '.join(str(p.number) for p in plates)} of {Path(static_c3d).name}"


def _file_bodymass(static_c3d: PathLike, why: str) -> tuple[float, str]:
    """The file's ``PROCESSING:Bodymass`` (kg) when its plates cannot weigh the subject (``why``), with where it
    came from; a stop asking for ``mass_kg`` without it."""
    bodymass = _processing(static_c3d).get("Bodymass")
    if bodymass is not None and 0 < bodymass <= 300:
        return float(bodymass), f"PROCESSING:Bodymass of {Path(static_c3d).name} ({why})"
    raise LoperInputError(
        f"{static_c3d}: no body mass: {why}, and the file has no PROCESSING:Bodymass; give mass_kg in the subject sheet"
    )


def _feet_off_plates(static_c3d: PathLike, plates, vertical_n: np.ndarray, window, up) -> str:
    """Why the plates do not weigh the whole subject ('' when they do): foot markers of the static trial's mean
    pose over no loaded plate (:func:`loper_analysis.motion.static_trial.markers_off_plates`)."""
    from loper_analysis.gait.grf import LOADED_THRESHOLD_N
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.motion.static_trial import FOOT_MARKER_HEIGHT_M, markers_off_plates

    rec = read_c3d(static_c3d)
    t = plates[0].time_s
    in_window = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    loaded = [p for j, p in enumerate(plates) if np.nanmean(vertical_n[in_window, j]) > LOADED_THRESHOLD_N]
    floor = float(np.mean([p.corners_m @ up for p in plates]))
    frames = (rec.time_s >= window[0] - 1e-9) & (rec.time_s <= window[1] + 1e-9)
    if not frames.any() or not len(rec.marker_labels):
        return ""
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a marker missing throughout: NaN, skipped
        pose = np.nanmean(rec.markers_m[frames], axis=0)
    _, off = markers_off_plates(pose, rec.marker_labels, [p.corners_m for p in loaded], up, floor)
    if not off:
        return ""
    numbers = ", ".join(str(p.number) for p in loaded) or "none"
    return (
        f"the plates do not carry the whole subject: foot markers {', '.join(off)} (lower than "
        f"{FOOT_MARKER_HEIGHT_M} m) stand beside the loaded plates ({numbers}) in the scaling window"
    )


def _processing(static_c3d: PathLike) -> dict[str, float]:
    """The ``PROCESSING`` parameters of a C3D file (Nexus: ``Bodymass`` kg, ``Height`` mm)."""
    from loper_analysis.io.c3d import read_c3d

    return read_c3d(static_c3d).processing


def _subject_height(height_m: float | None, static_c3d: PathLike | None, scaled, segment_bodies) -> tuple[float, str]:
    """The subject's height (m) and where it came from: given, the static trial's ``PROCESSING:Height`` (mm, as
    Nexus writes it), or estimated from the scaled model
    (:func:`loper_analysis.motion.static_trial.model_height_m`)."""
    from loper_analysis.motion.segments import segment_body_names
    from loper_analysis.motion.static_trial import model_height_m

    if height_m is not None:
        return float(height_m), "given"
    if static_c3d is not None:
        height_mm = _processing(static_c3d).get("Height")
        if height_mm is not None and 500 <= height_mm <= 2500:
            return height_mm / 1000.0, f"PROCESSING:Height of {Path(static_c3d).name}"
    thigh = segment_body_names(scaled, "r", segment_bodies)["thigh"][0]
    return model_height_m(scaled, thigh), "estimated from the scaled model"


def _model_stature(scaled, segment_bodies) -> float:
    """The scaled model's stature (m; :func:`loper_analysis.motion.static_trial.model_height_m`)."""
    from loper_analysis.motion.segments import segment_body_names
    from loper_analysis.motion.static_trial import model_height_m

    return model_height_m(scaled, segment_body_names(scaled, "r", segment_bodies)["thigh"][0])


def _require_stature(height: tuple[float, str], stature_m: float, static_trc: PathLike) -> None:
    """Refuse a scaled model whose stature differs from a height given (sheet or file) by more than
    :data:`loper_analysis.motion.scale_report.STOP_STATURE_CHANGE`: another subject's static trial."""
    from loper_analysis.motion.scale_report import STOP_STATURE_CHANGE, stature_change

    if height[1] == "estimated from the scaled model":
        return
    change = stature_change(height[0], stature_m)
    if np.isfinite(change) and abs(change) > STOP_STATURE_CHANGE:
        raise LoperInputError(
            f"{static_trc}: the model scaled to this static trial stands {stature_m:.2f} m tall where the "
            f"subject's height is {height[0]:.2f} m ({height[1]}; {100 * change:+.0f} %, more than "
            f"{100 * STOP_STATURE_CHANGE:.0f} %): is the static trial this subject's, and the height in the "
            "subject sheet (height_m) right?"
        )


def _lab_static(lab_angles_tsv: PathLike, window: tuple[float, float]) -> dict[str, float]:
    """The lab's own joint angles of the static trial (rad), averaged over the scaling window."""
    table = read_tsv(lab_angles_tsv, "lab angles", ("time_s",))
    if not len(table):
        return {}
    t = table["time_s"].to_numpy(float)
    inside = (t >= window[0] - 1e-9) & (t <= window[1] + 1e-9)
    return (
        {c.removesuffix("_rad"): float(np.nanmean(table.loc[inside, c])) for c in table.columns if c.endswith("_rad")}
        if inside.any()
        else {}
    )


def _scale_factors(scale_file: Path) -> dict[str, tuple[float, float, float]]:
    """Body -> scale factors (x, y, z) of the ScaleSet OpenSim wrote (empty when it wrote none)."""
    from loper_analysis.io.osim import quiet_opensim

    if not scale_file.is_file():
        return {}
    osim = quiet_opensim()
    scales = osim.ScaleSet(str(scale_file))
    out = {}
    for i in range(scales.getSize()):
        sc = scales.get(i)
        if sc.getApply():
            f = sc.getScaleFactors()
            out[sc.getSegmentName()] = (f.get(0), f.get(1), f.get(2))
    return out


def _placer_tasks(placer) -> tuple[dict[str, float], dict] | None:
    """Marker weights and coordinate tasks of the marker placer (None when it does not apply)."""
    from loper_analysis.io.ik_tasks import task_set_tasks

    if not placer.getApply():
        return None
    return task_set_tasks(placer.getIKTaskSet(), "MarkerPlacer/IKTaskSet")


def _names(object_set) -> list[str]:
    return [object_set.get(i).getName() for i in range(object_set.getSize())]


def _setup_file(name: str, setup_xml: Path) -> Path | None:
    """A file named in a setup, relative to the setup's folder (as OpenSim reads it); None when unset."""
    name = (name or "").strip()
    if name in ("", "Unassigned"):
        return None
    path = Path(name)
    return (path if path.is_absolute() else setup_xml.parent / path).resolve()


def _measurement_pairs(tool) -> dict[str, list[tuple[str, str]]]:
    """Marker pairs of each applied measurement of a ScaleTool (empty when its model scaler does not measure)."""
    scaler = tool.getModelScaler()
    order = scaler.getScalingOrder()
    if not scaler.getApply() or "measurements" not in [order.get(i) for i in range(order.getSize())]:
        return {}
    out: dict[str, list[tuple[str, str]]] = {}
    measurements = scaler.getMeasurementSet()
    for i in range(measurements.getSize()):
        m = measurements.get(i)
        if m.getApply():
            pairs = [m.getMarkerPair(j) for j in range(m.getNumMarkerPairs())]
            out[m.getName()] = [(p.getMarkerName(0), p.getMarkerName(1)) for p in pairs]
    return out


def _measurement_markers(tool) -> set[str]:
    """Markers of the applied measurements of a ScaleTool (empty when its model scaler does not measure)."""
    return {m for pairs in _measurement_pairs(tool).values() for pair in pairs for m in pair}
