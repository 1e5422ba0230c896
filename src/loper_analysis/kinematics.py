"""Inverse kinematics through OpenSim, in memory, plus forward marker kinematics.

One ``InverseKinematicsSolver`` is reused for all frames (far faster than
``InverseKinematicsTool`` per call); markers enter as a ``TimeSeriesTableVec3``
in metres with its ``Units`` metadata set (PITFALLS.md). Missing (NaN) markers
are dropped by OpenSim in that frame. Coordinate tasks (e.g. locking a
coordinate at its default) are honoured.

Task specification: ``marker_weights`` {marker: weight} and
``coordinate_tasks`` {coordinate: (weight, value or None)} where ``None``
means the coordinate's default value. Without marker weights every model
marker present in the data gets weight 1. :func:`read_ik_tasks` reads an
OpenSim IK task-set XML or a TSV (``name``, ``kind`` = marker|coordinate,
``weight``, optional ``value``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from .errors import LoperInputError
from .model import quiet_opensim

__all__ = [
    "IKResult",
    "marker_positions",
    "markers_table",
    "inverse_kinematics",
    "read_ik_tasks",
]


@dataclass
class IKResult:
    """IK output: ``coordinates`` (n_frames, n_coordinates) in rad or m, in model order."""

    time_s: np.ndarray
    coordinates: np.ndarray
    coordinate_names: list[str]
    marker_rms_m: np.ndarray
    marker_max_m: np.ndarray

    def frame(self) -> pd.DataFrame:
        """Tidy-wide table: time_s plus one column per coordinate (rad or m)."""
        return pd.DataFrame(self.coordinates, columns=self.coordinate_names).assign(time_s=self.time_s)[
            ["time_s", *self.coordinate_names]
        ]


def _load(model):
    osim = quiet_opensim()
    if isinstance(model, (str, Path)):
        if not Path(model).is_file():
            raise LoperInputError(f"model file not found: {model}")
        model = osim.Model(str(model))
    return osim, model


def marker_positions(model, coordinate_values: dict[str, np.ndarray], marker_names=None) -> np.ndarray:
    """Ground positions (n, n_markers, 3) in m of markers for coordinate trajectories (rad or m).

    Coordinates not given stay at their defaults.
    """
    osim, model = _load(model)
    state = model.initSystem()
    cs = model.getCoordinateSet()
    names = [cs.get(i).getName() for i in range(cs.getSize())]
    unknown = [c for c in coordinate_values if c not in names]
    if unknown:
        raise LoperInputError(f"model {model.getName()}: unknown coordinate(s) {unknown}; has {names}")
    values = {c: np.atleast_1d(np.asarray(v, float)) for c, v in coordinate_values.items()}
    n = max((len(v) for v in values.values()), default=1)
    ms = model.getMarkerSet()
    all_markers = [ms.get(i).getName() for i in range(ms.getSize())]
    wanted = list(all_markers if marker_names is None else marker_names)
    missing = [mk for mk in wanted if mk not in all_markers]
    if missing:
        raise LoperInputError(f"model {model.getName()}: marker(s) {missing} not in the model")
    idx = [all_markers.index(mk) for mk in wanted]
    out = np.empty((n, len(wanted), 3))
    for k in range(n):
        for c, v in values.items():
            cs.get(c).setValue(state, float(v[k if len(v) > 1 else 0]), False)
        model.realizePosition(state)
        for j, i in enumerate(idx):
            p = ms.get(i).getLocationInGround(state)
            out[k, j] = (p.get(0), p.get(1), p.get(2))
    return out


def markers_table(time_s, markers_m, labels):
    """An OpenSim ``TimeSeriesTableVec3`` (Units = m) from arrays (n,), (n, m, 3)."""
    osim = quiet_opensim()
    t = np.asarray(time_s, float)
    X = np.asarray(markers_m, float)
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] != t.size or X.shape[1] != len(labels):
        raise LoperInputError(
            f"markers_m must have shape (n_frames={t.size}, n_labels={len(labels)}, 3), got {X.shape}"
        )
    flat = np.ascontiguousarray(X.reshape(t.size, -1))
    cols = osim.StdVectorString([f"{lab}_{a}" for lab in labels for a in "xyz"])
    table = osim.TimeSeriesTable(osim.StdVectorDouble(list(t)), osim.Matrix.createFromMat(flat), cols)
    v3 = table.packVec3(osim.StdVectorString(["_x", "_y", "_z"]))
    v3.addTableMetaDataString("Units", "m")
    return v3


def inverse_kinematics(
    model,
    time_s,
    markers_m,
    labels,
    marker_weights: dict[str, float] | None = None,
    coordinate_tasks: dict[str, tuple[float, float | None]] | None = None,
    accuracy: float = 1e-8,
) -> IKResult:
    """OpenSim IK of marker trajectories (m) with one reused solver.

    Raises
    ------
    LoperInputError
        A weighted marker missing from the model or from the data, a
        coordinate task on an unknown coordinate, no model marker in the data.
    """
    osim, model = _load(model)
    labels = list(labels)
    t = np.asarray(time_s, float)
    if t.ndim != 1 or t.size < 1 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise LoperInputError("time_s must be finite and strictly increasing")
    ms = model.getMarkerSet()
    model_markers = [ms.get(i).getName() for i in range(ms.getSize())]
    if marker_weights is None:
        marker_weights = {mk: 1.0 for mk in labels if mk in model_markers}
        if not marker_weights:
            raise LoperInputError(f"none of the data's markers {labels[:8]}... is in model {model.getName()}")
    not_in_model = [mk for mk in marker_weights if mk not in model_markers]
    if not_in_model:
        raise LoperInputError(f"marker(s) {not_in_model} of the IK tasks are not in model {model.getName()}")
    not_in_data = [mk for mk, w in marker_weights.items() if w > 0 and mk not in labels]
    if not_in_data:
        raise LoperInputError(f"marker(s) {not_in_data} of the IK tasks are not in the marker data")
    keep = [i for i, lab in enumerate(labels) if lab in marker_weights and marker_weights[lab] > 0]
    X = np.asarray(markers_m, float)[:, keep, :]
    kept_labels = [labels[i] for i in keep]
    table = markers_table(t, X, kept_labels)
    weights = osim.SetMarkerWeights()
    for mk in kept_labels:
        weights.cloneAndAppend(osim.MarkerWeight(mk, float(marker_weights[mk])))
    mref = osim.MarkersReference(table, weights)
    cs = model.getCoordinateSet()
    names = [cs.get(i).getName() for i in range(cs.getSize())]
    cref = osim.SimTKArrayCoordinateReference()
    for cname, (w, value) in (coordinate_tasks or {}).items():
        if cname not in names:
            raise LoperInputError(f"coordinate task on '{cname}': not a coordinate of model {model.getName()}; has {names}")
        v = cs.get(cname).getDefaultValue() if value is None else float(value)
        ref = osim.CoordinateReference(cname, osim.Constant(v))
        ref.setWeight(float(w))
        cref.push_back(ref)
    state = model.initSystem()
    solver = osim.InverseKinematicsSolver(model, mref, cref, float("inf"))
    solver.setAccuracy(float(accuracy))
    state.setTime(float(t[0]))
    solver.assemble(state)
    Q = np.empty((t.size, len(names)))
    n_m = solver.getNumMarkersInUse()
    rms = np.empty(t.size)
    mx = np.empty(t.size)
    errs = osim.SimTKArrayDouble()
    for k in range(t.size):
        state.setTime(float(t[k]))
        solver.track(state)
        for i in range(len(names)):
            Q[k, i] = cs.get(i).getValue(state)
        solver.computeCurrentMarkerErrors(errs)
        e = np.array([errs.getElt(j) for j in range(n_m)])
        e = e[np.isfinite(e)]
        rms[k] = np.sqrt(np.mean(e**2)) if e.size else np.nan
        mx[k] = e.max() if e.size else np.nan
    return IKResult(time_s=t, coordinates=Q, coordinate_names=names, marker_rms_m=rms, marker_max_m=mx)


def read_ik_tasks(path) -> tuple[dict[str, float], dict[str, tuple[float, float | None]]]:
    """Marker weights and coordinate tasks from an OpenSim IK task-set XML or a TSV.

    TSV columns: ``name``, ``kind`` (marker | coordinate), ``weight`` and
    optional ``value`` (coordinate tasks; empty = the default value). Tasks with
    ``apply`` false in the XML are skipped; XML coordinate tasks with value type
    ``manual_value`` use their value, ``default_value`` the model default.
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"IK task file not found: {path}")
    markers: dict[str, float] = {}
    coords: dict[str, tuple[float, float | None]] = {}
    if path.suffix.lower() == ".xml":
        osim = quiet_opensim()
        try:
            ts = osim.IKTaskSet(str(path))
        except Exception as exc:
            raise LoperInputError(f"{path}: not an OpenSim IK task set ({exc})") from exc
        if ts.getSize() == 0:
            raise LoperInputError(f"{path}: the IK task set holds no task")
        for i in range(ts.getSize()):
            task = ts.get(i)
            if not task.getApply():
                continue
            if task.getConcreteClassName() == "IKMarkerTask":
                markers[task.getName()] = task.getWeight()
            else:
                ct = osim.IKCoordinateTask.safeDownCast(task)
                vt = ct.getValueType()
                if vt == osim.IKCoordinateTask.FromFile:
                    raise LoperInputError(f"{path}: coordinate task {task.getName()} takes its value from a file; not supported")
                value = ct.getValue() if vt == osim.IKCoordinateTask.ManualValue else None
                coords[task.getName()] = (task.getWeight(), value)
        return markers, coords
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
