"""File steps of the subject's OpenSim model: the generic model, scaling to the static trial, the segment table."""

from __future__ import annotations

import logging

from ..dynamics import SegmentParameters, segment_parameters_from_anthropometry
from ..errors import LoperInputError
from ..io.atomic import PathLike, staged, write_tsv
from ..io.readers import read_tsv

__all__ = ["SEGMENT_FLOAT_FORMAT", "read_segments", "write_segments", "generic_model", "scaled_model", "segments",
           "anthropometric_segments"]

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


def scaled_model(generic_osim: PathLike, static_trc: PathLike, out_osim: PathLike, mass_kg: float,
                 time_range_s: tuple[float, float] | None = None) -> None:
    """Personalise the generic model with OpenSim's ScaleTool from a static trial (TRC).

    Each body is scaled uniformly by the ratio of the marker-pair distances in
    the static trial to those of the model
    (:data:`loper_analysis.model.SCALE_MEASUREMENTS`); the mass distribution
    is preserved at ``mass_kg``. The static markers must be complete
    (:func:`loper_analysis.model.static_marker_problem`).
    """
    from pathlib import Path

    from ..io.opensim_tables import read_markers
    from ..io.osim import quiet_opensim
    from ..model import SCALE_MEASUREMENTS, static_marker_problem

    generic_osim, static_trc = Path(generic_osim), Path(static_trc)
    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    times, X, labels = read_markers(static_trc)
    static_marker_problem(times, X, labels, time_range_s, source=str(static_trc))
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


def segments(model_osim: PathLike, out_tsv: PathLike, side: str = "left", height_m: float | None = None,
             mass_kg: float | None = None, user_model: bool = False) -> SegmentParameters:
    """Segment table of the swing leg (TSV) for the dynamics model.

    From the scaled model; for a user-supplied model (whose bodies need not be
    ours) from Winter's table with the subject's height and mass.
    """
    from ..constants import SIDE_SUFFIX
    from ..io.osim import read_model
    from ..model import segment_parameters_from_model

    if user_model:
        if height_m is None or mass_kg is None:
            raise LoperInputError(f"{model_osim}: a user model needs the subject's height_m and mass_kg for its segment table")
        params = segment_parameters_from_anthropometry(height_m, mass_kg)
    else:
        params = segment_parameters_from_model(read_model(model_osim), side=SIDE_SUFFIX[side])
    write_segments(params, out_tsv)
    log.info("segment table of %s", model_osim)
    return params


def anthropometric_segments(out_tsv: PathLike, height_m: float, mass_kg: float,
                            attachment_fraction: float = 0.8) -> SegmentParameters:
    """Segment table from height and mass with Winter's table (the validation study's subject, the CLI)."""
    params = segment_parameters_from_anthropometry(height_m, mass_kg, attachment_fraction)
    write_segments(params, out_tsv)
    log.info("segment table for %s m, %s kg: %s", height_m, mass_kg, params)
    return params
