"""OpenSim's ``InverseKinematicsSolver`` over a trial, one solver reused for all frames.

Markers enter as a ``TimeSeriesTableVec3`` in metres (:func:`markers_table`);
coordinate tasks as ``CoordinateReference`` objects. The solver assembles the first frame from the model's
default pose and tracks every later one from the previous frame's solution. Called by
:func:`loper_analysis.motion.ik.inverse_kinematics` with ``solver="opensim"``, or when a model's kinematic
tree cannot be used.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import model_source, quiet_opensim

__all__ = ["markers_table", "opensim_marker_positions", "opensim_solution"]


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


def opensim_marker_positions(model, coordinate_values: dict[str, np.ndarray], marker_names: list[str]) -> np.ndarray:
    """Ground positions (n, n_markers, 3) in m of the model's markers ``marker_names``, OpenSim placing them frame
    by frame for coordinate trajectories ``coordinate_values`` (name -> (n,) or (1,) values, rad or m; the others
    at their defaults), set without enforcing the constraints. Names are not checked here
    (:func:`loper_analysis.motion.ik.marker_positions` does)."""
    state = model.initSystem()
    cs, ms = model.getCoordinateSet(), model.getMarkerSet()
    n = max((np.size(v) for v in coordinate_values.values()), default=1)
    # Look the coordinates and markers up once: per-frame lookups through SWIG cost more than the kinematics.
    coordinates = [(cs.get(c), np.broadcast_to(np.asarray(v, float), (n,))) for c, v in coordinate_values.items()]
    markers = [ms.get(name) for name in marker_names]
    out = np.empty((n, len(markers), 3))
    for k in range(n):
        for coordinate, v in coordinates:
            coordinate.setValue(state, float(v[k]), False)
        model.realizePosition(state)
        out[k] = [marker.getLocationInGround(state).to_numpy() for marker in markers]
    return out


def opensim_solution(
    model, t, X, labels, marker_weights, *, coordinate_tasks, frames, accuracy, source
) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """OpenSim IK of the frames ``frames`` of marker trajectories ``X`` (n_frames, n_markers, 3) in m.

    Parameters
    ----------
    model : opensim.Model
    t : ndarray, shape (n_frames,)
        Time (s).
    labels : list of str
        The model marker of each column of ``X``; ``marker_weights`` {marker: weight}.
    coordinate_tasks : dict
        {coordinate: (weight, value in rad or m, or None for the default)}.
    frames : ndarray of int
        The frames to solve, increasing; the others are NaN.
    accuracy : float
        The solver's accuracy (``setAccuracy``; config ``ik.opensim_accuracy``): unitless, roughly the number
        of correct digits asked of the weighted objective's minimum (1e-6: about six; OpenSim's default 1e-5).

    Returns
    -------
    (ndarray, ndarray, list of str)
        Coordinates (n_frames, n_coordinates) in rad or m in coordinate-set order, each marker in use's
        distance error (n_frames, n_in_use) in m (0 where OpenSim found it missing) and the markers in use.
    """
    osim = quiet_opensim()
    table = markers_table(t, X, labels)
    weights = osim.SetMarkerWeights()
    for mk in labels:
        weights.cloneAndAppend(osim.MarkerWeight(mk, float(marker_weights[mk])))
    mref = osim.MarkersReference(table, weights)
    cs = model.getCoordinateSet()
    names = [cs.get(i).getName() for i in range(cs.getSize())]
    cref = _coordinate_references(osim, model, names, coordinate_tasks, source)
    state = model.initSystem()
    perm = _q_order(model, state, cs)
    solver = osim.InverseKinematicsSolver(model, mref, cref, float("inf"))
    solver.setAccuracy(float(accuracy))
    state.setTime(float(t[frames[0]]))
    solver.assemble(state)
    Q, E = _tracked(osim, solver, state, t, frames)
    in_use_names = [solver.getMarkerNameForIndex(j) for j in range(E.shape[1])]
    return Q[:, perm], E, in_use_names


def _coordinate_references(osim, model, names: list[str], coordinate_tasks, source: str):
    """OpenSim's coordinate references of the coordinate tasks ({coordinate: (weight, value in rad or m, or
    None for the default)}); ``names`` are the model's coordinates, ``osim`` the opensim module. An unknown
    coordinate raises LoperInputError."""
    where = f"{source}: " if source else ""
    cs = model.getCoordinateSet()
    cref = osim.SimTKArrayCoordinateReference()
    for cname, (w, value) in (coordinate_tasks or {}).items():
        if cname not in names:
            raise LoperInputError(
                f"{where}coordinate task on '{cname}': not a coordinate of {model_source(model)}; has {names}"
            )
        v = cs.get(cname).getDefaultValue() if value is None else float(value)
        ref = osim.CoordinateReference(cname, osim.Constant(v))
        ref.setWeight(float(w))
        cref.push_back(ref)
    return cref


def _tracked(osim, solver, state, t: np.ndarray, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The generalised coordinates Q (n_frames, n_q) in state order and each marker in use's distance error
    (n_frames, n_markers_in_use) in m, tracked by the assembled ``solver`` at the frames ``frames`` of ``t`` (s);
    NaN in the other frames (``osim``: the opensim module)."""
    Q = np.full((t.size, state.getNQ()), np.nan)
    n_m = solver.getNumMarkersInUse()
    E = np.full((t.size, n_m), np.nan)  # marker distance errors (m)
    errs = osim.SimTKArrayDouble()
    get_elt, track, set_time, get_q = errs.getElt, solver.track, state.setTime, state.getQ
    compute_errors, markers_in_use = solver.computeCurrentMarkerErrors, range(n_m)
    for k in frames:  # the hot loop: one SWIG call per quantity
        set_time(float(t[k]))
        track(state)
        Q[k] = get_q().to_numpy()
        compute_errors(errs)
        E[k] = [get_elt(j) for j in markers_in_use]
    return Q, E


def _q_order(model, state, cs) -> np.ndarray:
    """Index into the state's Q of each coordinate of the coordinate set (found by setting distinct values).

    Locked coordinates (Rajagopal2016's subtalar, mtp and wrist angles) are
    unlocked in a copy of the state for the probe: a locked coordinate keeps
    its value when set. Coupled coordinates are set without enforcing their
    constraints, so every coordinate takes its own probe value.
    """
    probe = model.initSystem() if state is None else state.__class__(state)
    values = 0.001 * (np.arange(cs.getSize()) + 1)
    for i in range(cs.getSize()):
        coordinate = cs.get(i)
        if coordinate.getLocked(probe):
            coordinate.setLocked(probe, False)
        coordinate.setValue(probe, float(values[i]), False)
    q = probe.getQ().to_numpy()
    perm = np.array([int(np.argmin(np.abs(q - v))) for v in values])
    wrong = [cs.get(i).getName() for i in range(cs.getSize()) if not np.isclose(q[perm[i]], values[i])]
    shared = sorted({cs.get(i).getName() for i in range(cs.getSize()) for j in range(i) if perm[i] == perm[j]})
    if wrong or shared:
        raise LoperInputError(
            f"{model_source(model)}: coordinate(s) {', '.join(wrong or shared)} do not map one to one onto the "
            "state's generalised coordinates (Q); IK cannot report them"
        )
    return perm
