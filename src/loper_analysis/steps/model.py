"""File steps of the subject's OpenSim model: the generic model, scaling to the static trial, the segment table."""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from pathlib import Path

from ..dynamics import SegmentParameters, segment_parameters_from_anthropometry
from ..errors import LoperInputError
from ..io.atomic import PathLike, staged, write_tsv
from ..io.readers import read_tsv

__all__ = ["SEGMENT_FLOAT_FORMAT", "read_segments", "write_segments", "generic_model", "scaled_model",
           "scale_with_setup", "scale", "segments_from_model_file", "anthropometric_segments"]

log = logging.getLogger(__name__)

#: Significant digits of the segment table.
SEGMENT_FLOAT_FORMAT = "%.10g"


def write_segments(params: SegmentParameters, path: PathLike) -> None:
    """Write the segment table (:meth:`~loper_analysis.dynamics.SegmentParameters.to_frame`) as TSV."""
    write_tsv(params.to_frame(), path, SEGMENT_FLOAT_FORMAT)


def read_segments(path: PathLike) -> SegmentParameters:
    """The segment table written by :func:`write_segments`."""
    return SegmentParameters.from_frame(read_tsv(path, "segment table"), source=str(path))


def generic_model(out_osim: PathLike, height_m: float, mass_kg: float) -> None:
    """The generic lower-body model (:func:`loper_analysis.model.build_lower_body_model`) for this subject."""
    from ..io.osim import write_model
    from ..model import build_lower_body_model

    write_model(build_lower_body_model(height_m, mass_kg), out_osim)
    log.info("generic model for %s m, %s kg: %s", height_m, mass_kg, out_osim)


def _check_factors(model, measurements, times, X, labels, time_range_s, static_trc, factor_range) -> None:
    """Refuse scale factors outside ``factor_range`` (:func:`loper_analysis.plausibility.require_scale_factors`)."""
    import numpy as np

    from ..plausibility import measurement_scale_factors, require_scale_factors

    t0, t1 = (times[0], times[-1]) if time_range_s is None else time_range_s
    sel = (times >= t0 - 1e-9) & (times <= t1 + 1e-9)
    factors = measurement_scale_factors(model, measurements, np.asarray(X)[sel], labels)
    require_scale_factors(factors, str(static_trc), factor_range)


def scaled_model(generic_osim: PathLike, static_trc: PathLike, out_osim: PathLike, mass_kg: float,
                 time_range_s: tuple[float, float] | None = None,
                 factor_range: Sequence[float] = (0.5, 2.0)) -> None:
    """Personalise the generic model with OpenSim's ScaleTool from a static trial (TRC).

    Each body is scaled uniformly by the ratio of the marker-pair distances in
    the static trial to those of the model
    (:data:`loper_analysis.model.SCALE_MEASUREMENTS`); the mass distribution
    is preserved at ``mass_kg``. The static markers must be complete
    (:func:`loper_analysis.model.static_marker_problem`) and every factor must
    lie in ``factor_range`` (a factor near 10 or 1000 means markers in
    another unit than the TRC declares); nothing is written otherwise.
    """
    from pathlib import Path

    from ..io.opensim_tables import read_markers
    from ..io.osim import quiet_opensim, read_model
    from ..model import SCALE_MEASUREMENTS, static_marker_problem

    generic_osim, static_trc = Path(generic_osim), Path(static_trc)
    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    times, X, labels = read_markers(static_trc)
    static_marker_problem(times, X, labels, time_range_s, source=str(static_trc))
    _check_factors(read_model(generic_osim), SCALE_MEASUREMENTS, times, X, labels, time_range_s, static_trc,
                   factor_range)
    t0, t1 = (times[0], times[-1]) if time_range_s is None else time_range_s
    osim = quiet_opensim()
    tool = osim.ScaleTool()
    tool.setSubjectMass(float(mass_kg))
    tool.getGenericModelMaker().setModelFileName(str(generic_osim))
    scaler = tool.getModelScaler()
    scaler.setApply(True)
    order = osim.ArrayStr()
    order.append("measurements")
    scaler.setScalingOrder(order)
    scaler.setMarkerFileName(str(static_trc))
    tr = osim.ArrayDouble()
    tr.append(float(t0))
    tr.append(float(t1))
    scaler.setTimeRange(tr)
    scaler.setPreserveMassDist(True)
    measurements = scaler.getMeasurementSet()
    for body, pairs in SCALE_MEASUREMENTS.items():
        m = osim.Measurement()
        m.setName(body)
        m.setApply(True)
        for a, b in pairs:
            m.getMarkerPairSet().cloneAndAppend(osim.MarkerPair(a, b))
        scale = osim.BodyScale()
        scale.setName(body)
        axes = osim.ArrayStr()
        for axis in "XYZ":
            axes.append(axis)
        scale.setAxisNames(axes)
        m.getBodyScaleSet().cloneAndAppend(scale)
        measurements.cloneAndAppend(m)
    tool.getMarkerPlacer().setApply(False)
    with staged(out_osim, "OpenSim model") as tmp:
        scaler.setOutputModelFileName(str(tmp))
        tool.run()  # returns False when the marker placer is off, even after a good scaling: the file tells
        if not tmp.is_file():
            raise LoperInputError(f"OpenSim ScaleTool failed for {static_trc} with {generic_osim}")
    log.info("scaled %s to %s", generic_osim, static_trc)


def scale(generic_osim: PathLike, static_trc: PathLike, out_osim: PathLike, mass_kg: float,
          setup_xml: PathLike | None = None, segment_bodies: Mapping[str, Sequence[str]] | None = None,
          factor_range: Sequence[float] = (0.5, 2.0)) -> None:
    """The subject's scaled model: with a lab's ScaleTool setup (:func:`scale_with_setup`) when ``setup_xml``
    is given, else with the generated model's marker-pair measurements (:func:`scaled_model`); scale factors
    outside ``factor_range`` are refused."""
    if setup_xml is None:
        scaled_model(generic_osim, static_trc, out_osim, mass_kg, factor_range=factor_range)
    else:
        scale_with_setup(generic_osim, setup_xml, static_trc, mass_kg, out_osim, segment_bodies=segment_bodies,
                         factor_range=factor_range)


def segments_from_model_file(model_osim: PathLike, out_tsv: PathLike, side: str = "left",
                             segment_bodies: Mapping[str, Sequence[str]] | None = None,
                             attachment_fraction: float = 0.8) -> SegmentParameters:
    """Segment table (TSV) of one leg of an OpenSim model file (:func:`loper_analysis.segments_from_model.segments_from_model`).

    Parameters
    ----------
    model_osim : path
        A (scaled) ``.osim`` model: gait2392, Rajagopal2016, our generated
        model or any model whose bodies ``segment_bodies`` names.
    out_tsv : path
        The table (:func:`write_segments`), written atomically.
    side : {"left", "right"}
        The swing leg.
    segment_bodies : mapping, optional
        Segment -> body names with ``{s}`` for the side suffix (setting
        ``opensim.segment_bodies``); ``None``: the model's own kind.
    attachment_fraction : float
        Rod attachment as a fraction of the thigh length, for a model without brace markers.

    Raises
    ------
    LoperInputError
        Missing or unreadable model, unknown side, a configured body missing.
    """
    from ..checks import side as check_side
    from ..constants import SIDE_SUFFIX
    from ..io.osim import read_model
    from ..segments_from_model import segments_from_model

    check_side(side, str(model_osim))
    params = segments_from_model(read_model(model_osim), SIDE_SUFFIX[side], segment_bodies, attachment_fraction,
                                 source=str(model_osim))
    write_segments(params, out_tsv)
    log.info("segment table of %s (%s leg)", model_osim, side)
    return params


def anthropometric_segments(out_tsv: PathLike, height_m: float, mass_kg: float,
                            attachment_fraction: float = 0.8) -> SegmentParameters:
    """Segment table from height and mass with Winter's table (the validation study's subject, the CLI)."""
    params = segment_parameters_from_anthropometry(height_m, mass_kg, attachment_fraction)
    write_segments(params, out_tsv)
    log.info("segment table for %s m, %s kg: %s", height_m, mass_kg, params)
    return params


def scale_with_setup(generic_osim: PathLike, setup_xml: PathLike, static_trc: PathLike, mass_kg: float,
                     out_osim: PathLike, time_range_s: tuple[float, float] | None = None,
                     segment_bodies: Mapping[str, Sequence[str]] | None = None,
                     factor_range: Sequence[float] = (0.5, 2.0)) -> None:
    """Scale a generic OpenSim model with a lab's own ScaleTool setup and a static trial (TRC).

    The setup (``opensim.ScaleTool(setup_xml)``) keeps its measurements,
    scale set, scaling order, mass-distribution flag, marker-placer tasks
    and its marker set file (resolved, like OpenSim does, relative to the
    setup's folder); replaced are the generic model file, the marker file
    of the model scaler and the marker placer (``static_trc``), the subject
    mass, the time range and the output files: only the final model is
    written, atomically, to ``out_osim`` (the marker placer's model when it
    applies, else the model scaler's).

    Parameters
    ----------
    generic_osim : path
        The generic ``.osim`` model.
    setup_xml : path
        An OpenSim ScaleTool setup.
    static_trc : path
        The static trial (``.trc``, any length unit OpenSim knows).
    mass_kg : float
        Subject mass, kg (0 .. 300).
    out_osim : path
        The scaled model.
    time_range_s : (float, float), optional
        Frames of the static trial used, s (default: the whole trial).
    segment_bodies : mapping, optional
        The bodies the segment table will need (``opensim.segment_bodies``);
        the scaled model must have them on both sides.
    factor_range : (float, float)
        Least and largest plausible factor of a measurement (static-trial
        marker distance over the model's at its default pose, averaged over
        the measurement's pairs; :func:`loper_analysis.plausibility.measurement_scale_factors`).

    Raises
    ------
    LoperInputError
        A missing file; a file that is not a ScaleTool setup; measurement
        markers that the model (with the setup's marker set) or the static
        trial lacks (all listed); a measurement marker missing (NaN) in a
        frame of the time range (ScaleTool would crash or scale with a wrong
        factor; markers used only by the marker placer may have gaps, OpenSim
        leaves such a marker where it is); a scaled model without the
        configured bodies; a measurement's scale factor outside
        ``factor_range`` (markers in another unit than the TRC declares);
        ScaleTool failing. Nothing is written then.
    """
    from ..io.opensim_tables import read_markers
    from ..io.osim import quiet_opensim, read_marker_set, read_model, read_scale_setup
    from ..model import static_marker_problem
    from ..segments_from_model import check_segment_bodies

    generic_osim, setup_xml, static_trc = Path(generic_osim), Path(setup_xml), Path(static_trc)
    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if static_trc.suffix.lower() != ".trc":
        raise LoperInputError(f"{static_trc}: ScaleTool reads a static trial as .trc, got '{static_trc.suffix}'")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    tool = read_scale_setup(setup_xml)
    maker = tool.getGenericModelMaker()
    marker_set = _setup_file(maker.getMarkerSetFileName(), setup_xml)
    if marker_set is not None and not marker_set.is_file():
        raise LoperInputError(f"{setup_xml}: GenericModelMaker/marker_set_file {maker.getMarkerSetFileName()} "
                              f"not found (looked for {marker_set})")
    generic = read_model(generic_osim)
    if marker_set is not None:
        generic.updateMarkerSet(read_marker_set(marker_set))  # as ScaleTool does: the set's markers replace or add
    model_markers = set(_names(generic.getMarkerSet()))
    needed = _measurement_markers(tool)
    lacking = sorted(needed - model_markers)
    if lacking:
        extra = f" with marker set {marker_set}" if marker_set is not None else ""
        raise LoperInputError(f"{setup_xml}: measurement marker(s) {lacking} are not on the model {generic_osim}{extra}")
    times, X, labels = read_markers(static_trc)
    lacking = sorted(needed - set(labels))
    if lacking:
        raise LoperInputError(f"{setup_xml}: measurement marker(s) {lacking} are not in the static trial {static_trc}")
    t0, t1 = (float(times[0]), float(times[-1])) if time_range_s is None else map(float, time_range_s)
    if not (t0 <= t1 and t0 <= times[-1] + 1e-9 and t1 >= times[0] - 1e-9):
        raise LoperInputError(f"{static_trc}: time_range_s {time_range_s} lies outside the trial "
                              f"({times[0]:.3f} .. {times[-1]:.3f} s) or is reversed")
    static_marker_problem(times, X, labels, (t0, t1), source=str(static_trc), needed=needed)
    _check_factors(generic, _measurement_pairs(tool), times, X, labels, (t0, t1), static_trc, factor_range)

    osim = quiet_opensim()
    tool.setPathToSubject("")  # OpenSim prefixes the setup's folder to every file name; ours are absolute
    tool.setSubjectMass(mass_kg)
    maker.setModelFileName(str(generic_osim.resolve()))
    maker.setMarkerSetFileName(str(marker_set) if marker_set is not None else "Unassigned")
    scaler, placer = tool.getModelScaler(), tool.getMarkerPlacer()
    time_range = osim.ArrayDouble()
    time_range.append(t0)
    time_range.append(t1)
    trc = str(static_trc.resolve())
    coordinates = _setup_file(placer.getCoordinateFileName(), setup_xml)
    placer.setCoordinateFileName(str(coordinates) if coordinates is not None else "Unassigned")
    for part in (scaler, placer):
        part.setMarkerFileName(trc)
        part.setTimeRange(time_range)
    scaler.setOutputScaleFileName("Unassigned")
    placer.setOutputMotionFileName("Unassigned")
    placer.setOutputMarkerFileName("Unassigned")
    with staged(out_osim, "OpenSim model") as tmp:
        final, other = (placer, scaler) if placer.getApply() else (scaler, placer)
        final.setOutputModelFileName(str(tmp))
        other.setOutputModelFileName("Unassigned")
        try:
            tool.run()
        except Exception as exc:  # OpenSim raises its own exception types
            raise LoperInputError(f"{setup_xml}: OpenSim's ScaleTool failed for {static_trc} with {generic_osim} "
                                  f"({exc})") from exc
        if not tmp.is_file():
            raise LoperInputError(f"{setup_xml}: OpenSim's ScaleTool wrote no model for {static_trc} with "
                                  f"{generic_osim} (are the model scaler and the marker placer both off?)")
        check_segment_bodies(read_model(tmp), segment_bodies, source=f"{out_osim} (scaled from {generic_osim})")
    log.info("scaled %s with %s to %s", generic_osim, setup_xml, static_trc)


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
