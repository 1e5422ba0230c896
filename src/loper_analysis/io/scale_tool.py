"""OpenSim's ScaleTool as a setup file holds it: time ranges, the files it names, its measurements, the marker
placer's tasks and the scale factors it wrote; and one run of the tool on a scaling window.

:func:`read_setup_tool` reads a lab's setup with the generic model and its marker set, checked;
:func:`run_scale_tool` points a tool at the generic model and the scaling window (written as the TRC the
tool reads), runs it in a temporary folder and reads back what it wrote (:class:`ScaleToolRun`). The
window, the static pose and the mass come from :mod:`loper_analysis.motion.scaling`.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = [
    "ScaleToolRun",
    "array_double",
    "measurement_markers",
    "measurement_pairs",
    "object_names",
    "placer_tasks",
    "read_scale_factors",
    "read_setup_tool",
    "run_scale_tool",
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


def measurement_bodies(tool) -> dict[str, list[str]]:
    """Bodies each applied measurement of a ScaleTool scales (empty when its model scaler does not measure)."""
    names = measurement_pairs(tool)
    measurements = tool.getModelScaler().getMeasurementSet()
    out = {}
    for i in range(measurements.getSize()):
        m = measurements.get(i)
        if m.getName() in names:
            scales = m.getBodyScaleSet()
            out[m.getName()] = [scales.get(j).getName() for j in range(scales.getSize())]
    return out


def measurement_markers(tool) -> set[str]:
    """Markers of the applied measurements of a ScaleTool (empty when its model scaler does not measure)."""
    return {m for pairs in measurement_pairs(tool).values() for pair in pairs for m in pair}


def read_setup_tool(setup_xml: Path, generic_osim: Path, static_trc: Path):
    """A lab's ScaleTool setup, the generic model with the setup's marker set and that marker set's file.

    Parameters
    ----------
    setup_xml, generic_osim, static_trc : Path
        The setup, the generic ``.osim`` model and the static trial (``.trc``). The marker set file the setup
        names (``GenericModelMaker/marker_set_file``) is resolved, as OpenSim does, relative to the setup's
        folder; its markers replace or add to the model's, as ScaleTool does.

    Returns
    -------
    tool : opensim.ScaleTool
    generic : opensim.Model
        The generic model with the setup's markers.
    marker_set : Path or None
        The marker set file (None: the setup names none).

    Raises
    ------
    LoperInputError
        A missing file; a static trial that is not ``.trc``; a file that is not a ScaleTool setup; a marker
        set file not found; measurement markers the model (with the setup's marker set) lacks (all listed).
    """
    from loper_analysis.io.osim import read_marker_set, read_model, read_scale_setup

    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if static_trc.suffix.lower() != ".trc":
        raise LoperInputError(f"{static_trc}: ScaleTool reads a static trial as .trc, got '{static_trc.suffix}'")
    tool = read_scale_setup(setup_xml)
    maker = tool.getGenericModelMaker()
    marker_set = setup_file(maker.getMarkerSetFileName(), setup_xml)
    if marker_set is not None and not marker_set.is_file():
        raise LoperInputError(
            f"{setup_xml}: GenericModelMaker/marker_set_file {maker.getMarkerSetFileName()} "
            f"not found (looked for {marker_set})"
        )
    generic = read_model(generic_osim)
    if marker_set is not None:
        generic.updateMarkerSet(read_marker_set(marker_set))  # as ScaleTool does: the set's markers replace or add
    model_markers = set(object_names(generic.getMarkerSet()))
    lacking = sorted(measurement_markers(tool) - model_markers)
    if lacking:
        extra = f" with marker set {marker_set}" if marker_set is not None else ""
        raise LoperInputError(
            f"{setup_xml}: measurement marker(s) {lacking} are not on the model {generic_osim}{extra}"
        )
    return tool, generic, marker_set


@dataclass(frozen=True)
class ScaleToolRun:
    """What one run of OpenSim's ScaleTool wrote, read back (:func:`run_scale_tool`).

    Attributes
    ----------
    model_osim : bytes
        The final model's file as the tool wrote it (the marker placer's model when it applies, else the model
        scaler's).
    scaled : opensim.Model
        That model.
    unplaced : opensim.Model or None
        The model scaler's model before marker placement; None when the marker placer or the model scaler is off.
    factors : dict
        Body -> scale factors (x, y, z) the model scaler applied (:func:`read_scale_factors`; empty when it
        scaled nothing).
    tasks : (dict, dict) or None
        The marker placer's marker weights and coordinate tasks (:func:`placer_tasks`); None when it does not
        apply.
    window_s : (float, float)
        The window (s) the tool averaged: the scaling window, or a snapshot's frame and the next
        (written by the run).
    """

    model_osim: bytes
    scaled: object
    unplaced: object | None
    factors: dict[str, tuple[float, float, float]]
    tasks: tuple | None
    window_s: tuple[float, float]


def run_scale_tool(
    tool,
    pose,
    window: tuple[float, float],
    ranges: dict,
    *,
    mass_kg: float,
    generic_osim: Path,
    static_trc: Path,
    out_name: str,
    marker_set: Path | None = None,
    setup_xml: Path | None = None,
) -> ScaleToolRun:
    """Run OpenSim's ScaleTool on the scaling window of a static trial and read back what it wrote.

    The tool gets the subject's mass, the generic model and marker set files (absolute: no path to the
    subject), the setup's coordinate file resolved beside ``setup_xml``, and the window's pose as a TRC (a
    snapshot static trial: its frame twice, a frame apart, as OpenSim averages over a span); it writes, in a
    temporary folder, the model, the scale set and the model before marker placement.

    Parameters
    ----------
    tool : opensim.ScaleTool
        A lab's setup (:func:`read_setup_tool`) or one built for the generated model.
    pose : loper_analysis.motion.static_trial.StaticPose
        The scaling window's frames (times s, shape (n,); markers m, shape (n, n_markers, 3)).
    window : (float, float)
        The scaling window (s).
    ranges : dict
        The model scaler's and marker placer's own time ranges (s), keyed by the tool's parts, None where unset
        (:func:`loper_analysis.motion.scaling.scaling_pose`).
    mass_kg : float
        The subject's mass (kg).
    generic_osim, static_trc : Path
        The generic model and the static trial (in messages; the static trial's data rate for a snapshot).
    out_name : str
        The final model's file name (the tool writes it under that name).
    marker_set : Path, optional
        The setup's marker set file (None: unassigned).
    setup_xml : Path, optional
        The setup the tool was read from (None: a tool built here; messages then name the static trial).

    Raises
    ------
    LoperInputError
        ScaleTool failing, or writing no model.
    """
    from loper_analysis.io.osim import read_model

    where = str(setup_xml) if setup_xml is not None else str(static_trc)
    placer = tool.getMarkerPlacer()
    maker = tool.getGenericModelMaker()
    tool.setPathToSubject("")  # OpenSim prefixes the setup's folder to every file name; ours are absolute
    tool.setSubjectMass(mass_kg)
    maker.setModelFileName(str(generic_osim.resolve()))
    maker.setMarkerSetFileName(str(marker_set) if marker_set is not None else "Unassigned")
    if setup_xml is not None:
        coordinates = setup_file(placer.getCoordinateFileName(), setup_xml)
        placer.setCoordinateFileName(str(coordinates) if coordinates is not None else "Unassigned")
    with tempfile.TemporaryDirectory(prefix="loper-scale-") as tmp_dir:
        trc, window = _window_file(tool, pose, ranges, window, Path(tmp_dir), static_trc)
        scale_file, unplaced_file = Path(tmp_dir) / "scale_set.xml", Path(tmp_dir) / "scaled_unplaced.osim"
        model = Path(tmp_dir) / "model" / out_name
        model.parent.mkdir()
        _run_tool(tool, (model, scale_file, unplaced_file), (trc, static_trc, generic_osim), where)
        return ScaleToolRun(
            model_osim=model.read_bytes(),
            scaled=read_model(model),
            unplaced=read_model(unplaced_file) if unplaced_file.is_file() else None,
            factors=read_scale_factors(scale_file),
            tasks=placer_tasks(placer),
            window_s=window,
        )


def _window_file(tool, pose, ranges: dict, window: tuple[float, float], tmp_dir: Path, static_trc: Path):
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
        part.setTimeRange(array_double(osim, own if own is not None else window))
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
