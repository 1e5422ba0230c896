"""OpenSim's ScaleTool as a setup file holds it: time ranges, the files it names, its measurements, the marker
placer's tasks and the scale factors it wrote.

Helpers of :func:`loper_analysis.steps.model.scale_with_setup` around the ``opensim.ScaleTool`` objects; the
tool itself reads the setup and the static trial.
"""

from __future__ import annotations

from pathlib import Path

__all__ = [
    "array_double",
    "measurement_markers",
    "measurement_pairs",
    "object_names",
    "placer_tasks",
    "read_scale_factors",
    "setup_file",
    "time_range",
]


def time_range(part) -> tuple[float, float] | None:
    """A model scaler's or marker placer's time range as the setup holds it (None without two numbers; OpenSim's
    unset ``-1 -1`` is judged by :func:`loper_analysis.motion.static_trial.time_range_is_set`)."""
    r = part.getTimeRange()
    return (r.get(0), r.get(1)) if r.getSize() >= 2 else None


def array_double(osim, pair) -> object:
    """An OpenSim ``ArrayDouble`` of the numbers of ``pair``."""
    out = osim.ArrayDouble()
    for value in pair:
        out.append(float(value))
    return out


def read_scale_factors(scale_file: Path) -> dict[str, tuple[float, float, float]]:
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


def placer_tasks(placer) -> tuple[dict[str, float], dict] | None:
    """Marker weights and coordinate tasks of the marker placer (None when it does not apply)."""
    from loper_analysis.io.ik_tasks import task_set_tasks

    if not placer.getApply():
        return None
    return task_set_tasks(placer.getIKTaskSet(), "MarkerPlacer/IKTaskSet")


def object_names(object_set) -> list[str]:
    """The names of the objects of an OpenSim set, in order."""
    return [object_set.get(i).getName() for i in range(object_set.getSize())]


def setup_file(name: str, setup_xml: Path) -> Path | None:
    """A file named in a setup, relative to the setup's folder (as OpenSim reads it); None when unset."""
    name = (name or "").strip()
    if name in ("", "Unassigned"):
        return None
    path = Path(name)
    return (path if path.is_absolute() else setup_xml.parent / path).resolve()


def measurement_pairs(tool) -> dict[str, list[tuple[str, str]]]:
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


def measurement_markers(tool) -> set[str]:
    """Markers of the applied measurements of a ScaleTool (empty when its model scaler does not measure)."""
    return {m for pairs in measurement_pairs(tool).values() for pair in pairs for m in pair}
