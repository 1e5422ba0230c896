"""OpenSim IK task files: marker weights and coordinate tasks from a task-set XML or a TSV."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import quiet_opensim
from loper_analysis.timing import timed_io

__all__ = ["read_ik_tasks", "task_set_tasks"]


def task_set_tasks(task_set, source: str) -> tuple[dict[str, float], dict[str, tuple[float, float | None]]]:
    """Marker weights and coordinate tasks of an ``opensim.IKTaskSet`` (of a file, an IK tool or a marker placer).

    Tasks with ``apply`` false are skipped; coordinate tasks with value type
    ``manual_value`` use their value, ``default_value`` the model default.

    Raises
    ------
    LoperInputError
        An empty task set, or a coordinate task taking its value from a file
        (naming ``source`` and the task).
    """
    osim = quiet_opensim()
    if task_set.getSize() == 0:
        raise LoperInputError(f"{source}: the IK task set holds no task")
    markers: dict[str, float] = {}
    coords: dict[str, tuple[float, float | None]] = {}
    for i in range(task_set.getSize()):
        task = task_set.get(i)
        if not task.getApply():
            continue
        if task.getConcreteClassName() == "IKMarkerTask":
            markers[task.getName()] = task.getWeight()
        else:
            ct = osim.IKCoordinateTask.safeDownCast(task)
            vt = ct.getValueType()
            if vt == osim.IKCoordinateTask.FromFile:
                raise LoperInputError(
                    f"{source}: coordinate task {task.getName()} takes its value from a file; not supported"
                )
            value = ct.getValue() if vt == osim.IKCoordinateTask.ManualValue else None
            coords[task.getName()] = (task.getWeight(), value)
    return markers, coords


def _holds_element(path: Path, element: str) -> bool:
    """Whether an XML file's root is, or directly holds, ``<element>`` (False for a file that is not XML)."""
    import xml.etree.ElementTree as ET

    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, UnicodeDecodeError):
        return False
    return root.tag == element or root.find(element) is not None


@timed_io
def read_ik_tasks(path: str | os.PathLike) -> tuple[dict[str, float], dict[str, tuple[float, float | None]]]:
    """Marker weights and coordinate tasks from an OpenSim IK task-set XML or a TSV.

    TSV columns: ``name``, ``kind`` (marker | coordinate), ``weight`` and
    optional ``value`` (coordinate tasks; empty = the default value). The XML
    is an ``IKTaskSet`` file or a whole ``InverseKinematicsTool`` setup (its
    task set is used; its model, marker file and time range are not). Tasks
    with ``apply`` false in the XML are skipped; XML coordinate tasks with
    value type ``manual_value`` use their value, ``default_value`` the model
    default.
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"IK task file not found: {path}")
    markers: dict[str, float] = {}
    coords: dict[str, tuple[float, float | None]] = {}
    if path.suffix.lower() == ".xml":
        osim = quiet_opensim()
        try:
            if _holds_element(path, "InverseKinematicsTool"):
                tool = osim.InverseKinematicsTool(str(path), False)  # False: without loading its model file
                ts = tool.getIKTaskSet()  # a reference into the tool, which must outlive it
            else:
                ts = osim.IKTaskSet(str(path))
        except Exception as exc:
            raise LoperInputError(f"{path}: not an OpenSim IK task set ({exc})") from exc
        return task_set_tasks(ts, str(path))
    try:
        df = pd.read_csv(path, sep="\t")
    except (OSError, pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise LoperInputError(f"{path}: cannot read IK task table ({exc})") from exc
    need = {"name", "kind", "weight"}
    if not need <= set(df.columns):
        raise LoperInputError(f"{path}: missing column(s) {sorted(need - set(df.columns))}")
    for row_no, r in enumerate(df.itertuples(index=False), start=1):
        w = pd.to_numeric(pd.Series([r.weight]), errors="coerce").iloc[0]
        if pd.isna(w) or w < 0:
            raise LoperInputError(f"{path}: row {row_no}, column weight: {r.weight!r} is not a weight >= 0")
        if r.kind == "marker":
            markers[str(r.name)] = float(w)
        elif r.kind == "coordinate":
            value = getattr(r, "value", np.nan) if "value" in df.columns else np.nan
            coords[str(r.name)] = (float(w), None if pd.isna(value) else float(value))
        else:
            raise LoperInputError(f"{path}: row {row_no}, column kind: {r.kind!r} is not 'marker' or 'coordinate'")
    return markers, coords
