"""Inverse dynamics: the generalised forces of a model's coordinates, their powers and their per-kg values.

:func:`generalized_forces` follows OpenSim's ``InverseDynamicsTool`` step by step, from objects in memory:

1. The coordinate trajectories (rad or m) go into an OpenSim ``Storage``. With a cut-off, the Storage is
   padded with half its length at each end (the signal reflected and negated about its end points, which
   keeps value and slope) and low-passed with OpenSim's ``lowpassIIR``: a 3rd-order Butterworth run forward
   and backward (zero lag, 6th order in effect, gain 1/2 at the cut-off).
2. A quintic generalised cross-validated spline (``GCVSplineSet(5, ...)``) of each coordinate gives its
   value, speed and acceleration at every frame.
3. The ground's loads on the feet (:class:`FootLoad`: force N, point m, free torque N·m, in ground) enter as
   ``ExternalForce`` objects on a copy of the model whose own forces (muscles, actuators, passive forces)
   are switched off; ``initSystem`` comes after they are added.
4. ``InverseDynamicsSolver`` returns, per frame, the generalised forces that reproduce the accelerations
   with gravity and the external loads, ignoring the constraints: N·m for rotational coordinates, N for
   translational ones, positive in the sense of the coordinate.

The same spline gives the speeds of :func:`coordinate_speeds`; :func:`joint_powers_w` multiplies moments
and speeds, :func:`normalised_per_kg` divides by a body mass. Every bad input raises
:class:`~loper_analysis.errors.LoperInputError` naming the input and the value.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from loper_analysis.checks import positive, time_vector, uniform_step_s
from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import model_source, quiet_opensim

if TYPE_CHECKING:
    import opensim

__all__ = [
    "FootLoad",
    "SPLINE_DEGREE",
    "coordinate_speeds",
    "generalized_forces",
    "joint_powers_w",
    "normalised_per_kg",
]

#: Degree of OpenSim's GCV splines of the coordinates (the InverseDynamicsTool's).
SPLINE_DEGREE = 5
#: Column suffixes of the generalised forces (N·m, N) and of their powers (W).
_MOMENT, _FORCE, _POWER = "_moment_nm", "_force_n", "_power_w"
_AXES = "xyz"


@dataclass(frozen=True)
class FootLoad:
    """The ground's load on one body (a foot), in the ground frame.

    Attributes
    ----------
    body : str
        The model body the load acts on (``calcn_r``).
    time_s : ndarray, shape (n,)
        Time (s), finite, strictly increasing; it must cover the coordinates' times.
    force_n : ndarray, shape (n, 3)
        Force of the ground on the body (N), ground frame.
    point_m : ndarray, shape (n, 3)
        Point of application (m), ground frame (any finite value where the force is zero).
    torque_nm : ndarray, shape (n, 3)
        Free torque (N·m), ground frame.
    """

    body: str
    time_s: np.ndarray
    force_n: np.ndarray
    point_m: np.ndarray
    torque_nm: np.ndarray


def _coordinate_table(
    model: opensim.Model, time_s, coordinates: pd.DataFrame
) -> tuple[np.ndarray, list[str], np.ndarray]:
    """Time (n,), names and values (n, k) of ``coordinates``, checked against the model."""
    t = time_vector(time_s, name="time_s", min_count=2 * SPLINE_DEGREE, item="frame")
    if not isinstance(coordinates, pd.DataFrame):
        raise LoperInputError(f"coordinates must be a pandas DataFrame, got {type(coordinates).__name__}")
    names = [str(c) for c in coordinates.columns]
    cs = model.getCoordinateSet()
    unknown = [c for c in names if not cs.contains(c)]
    if unknown:
        raise LoperInputError(f"coordinates: column '{unknown[0]}' is not a coordinate of {model_source(model)}")
    if not names:
        raise LoperInputError("coordinates: no coordinate columns")
    if len(set(names)) != len(names):
        raise LoperInputError(f"coordinates: repeated column names {sorted({c for c in names if names.count(c) > 1})}")
    if len(coordinates) != t.size:
        raise LoperInputError(f"coordinates must have one row per time_s value ({t.size}), got {len(coordinates)}")
    try:
        values = coordinates.to_numpy(dtype=float)
    except (TypeError, ValueError) as exc:
        raise LoperInputError(f"coordinates must be numeric: {exc}") from None
    bad = np.argwhere(~np.isfinite(values))
    if bad.size:
        i, j = bad[0]
        raise LoperInputError(f"coordinates: '{names[j]}' is not finite at frame {i} ({t[i]:g} s): {values[i, j]}")
    return t, names, values


def _storage(osim, t: np.ndarray, names: Sequence[str], values: np.ndarray):
    """An OpenSim ``Storage`` (not in degrees) of columns ``names`` over time ``t``."""
    storage = osim.Storage(int(t.size))
    labels = osim.ArrayStr()
    for name in ("time", *names):
        labels.append(name)
    storage.setColumnLabels(labels)
    storage.setInDegrees(False)
    for k in range(t.size):
        storage.append(osim.StateVector(float(t[k]), osim.Vector(values[k].tolist())))
    return storage


def _coordinate_splines(osim, t: np.ndarray, names: Sequence[str], values: np.ndarray, cutoff_hz: float | None):
    """OpenSim's ``GCVSplineSet`` of the coordinates, low-passed first as the InverseDynamicsTool does."""
    storage = _storage(osim, t, names, values)
    if cutoff_hz is not None:
        step = uniform_step_s(t, name="time_s")
        cutoff = positive("cutoff_hz", cutoff_hz)
        if cutoff >= 0.5 / step:
            raise LoperInputError(
                f"cutoff_hz must be below half the frame rate ({0.5 / step:.6g} Hz), got {cutoff_hz!r}"
            )
        storage.pad(storage.getSize() // 2)
        storage.lowpassIIR(cutoff)
    return osim.GCVSplineSet(SPLINE_DEGREE, storage), storage


def _spline_derivatives(splines, names: Sequence[str], t: np.ndarray, order: int) -> np.ndarray:
    """Derivative ``order`` (0: value) of each spline at times ``t``: shape (n, len(names))."""
    osim = quiet_opensim()
    out = np.empty((t.size, len(names)))
    components = osim.StdVectorInt([0] * order)
    for j, name in enumerate(names):
        spline = splines.get(name)
        for k, tk in enumerate(t):
            x = osim.Vector(1, float(tk))
            out[k, j] = spline.calcValue(x) if order == 0 else spline.calcDerivative(components, x)
    return out


def coordinate_speeds(
    model: opensim.Model, time_s: np.ndarray, coordinates: pd.DataFrame, *, cutoff_hz: float | None
) -> pd.DataFrame:
    """The coordinates' speeds at ``time_s``, from the splines :func:`generalized_forces` differentiates.

    Parameters
    ----------
    model : opensim.Model
        The model the coordinates belong to (checked, not changed).
    time_s : ndarray, shape (n_frames,)
        Frame times (s), strictly increasing (equally spaced with a cut-off), at least 10 frames.
    coordinates : pandas.DataFrame, shape (n_frames, n_coords)
        Coordinate values, rad or m; columns are coordinate names of ``model``.
    cutoff_hz : float or None
        Low-pass cut-off (Hz) of the coordinates, or None for none (see the module docstring).

    Returns
    -------
    pandas.DataFrame
        ``time_s`` and one column per coordinate, named like the coordinate: rad/s or m/s.

    Raises
    ------
    LoperInputError
        As :func:`generalized_forces`.
    """
    osim = quiet_opensim()
    t, names, values = _coordinate_table(model, time_s, coordinates)
    splines, _ = _coordinate_splines(osim, t, names, values, cutoff_hz)
    speeds = _spline_derivatives(splines, names, t, 1)
    return pd.DataFrame({"time_s": t, **{c: speeds[:, j] for j, c in enumerate(names)}})


def _load_arrays(load: FootLoad, index: int) -> tuple[np.ndarray, np.ndarray]:
    """Time (n,) and the (n, 9) force, point and torque of one load, checked."""
    where = f"loads[{index}]"
    if not isinstance(load, FootLoad):
        raise LoperInputError(f"{where} must be a FootLoad, got {type(load).__name__}")
    t = time_vector(load.time_s, source=where, name="time_s")
    parts = []
    for name in ("force_n", "point_m", "torque_nm"):
        a = np.asarray(getattr(load, name), dtype=float)
        if a.shape != (t.size, 3):
            raise LoperInputError(f"{where}: {name} must have shape ({t.size}, 3), got {a.shape}")
        bad = np.argwhere(~np.isfinite(a))
        if bad.size:
            raise LoperInputError(f"{where}: {name} is not finite at row {bad[0][0]}: {a[tuple(bad[0])]}")
        parts.append(a)
    return t, np.hstack(parts)


def _add_external_forces(osim, model, loads: Sequence[FootLoad], t_first: float, t_last: float) -> list:
    """Add one ``ExternalForce`` per load to ``model`` (force and point in ground); returns their Storages,
    which must outlive the model's use (the forces read them)."""
    storages = []
    bodies = model.getBodySet()
    for i, load in enumerate(loads):
        t, data = _load_arrays(load, i)
        if not bodies.contains(load.body):
            raise LoperInputError(f"loads[{i}]: body '{load.body}' is not a body of {model_source(model)}")
        if t[0] > t_first or t[-1] < t_last:
            raise LoperInputError(
                f"loads[{i}]: time_s {t[0]:g} .. {t[-1]:g} s does not cover the coordinates' "
                f"{t_first:g} .. {t_last:g} s"
            )
        prefix = f"load{i}_"
        names = [f"{prefix}{kind}{a}" for kind in ("force_v", "point_p", "torque_") for a in _AXES]
        storage = _storage(osim, t, names, data)
        force = osim.ExternalForce(
            storage, f"{prefix}force_v", f"{prefix}point_p", f"{prefix}torque_", load.body, "ground", "ground"
        )
        force.setName(f"{prefix}{load.body}")
        model.addForce(force)
        storages.append(storage)
    return storages


def _state_indices(osim, model, state, names: Sequence[str]) -> tuple[np.ndarray, np.ndarray]:
    """For each coordinate of ``names``, its index in the state's Q and in its U.

    Found by giving every state variable a distinct value, the coordinates unlocked (a locked one keeps its
    value): the state-variable order is not the state's Q order (Rajagopal2016's patellofemoral coordinates
    sit elsewhere). A model whose Q and U do not map one to one onto its coordinates (a ball joint's
    quaternion) is refused.
    """
    variables = model.getStateVariableNames()
    probe = osim.State(state)
    cs = model.getCoordinateSet()
    for i in range(cs.getSize()):
        cs.get(i).setLocked(probe, False)
    model.setStateVariableValues(probe, osim.Vector(np.arange(1.0, variables.getSize() + 1).tolist()))
    q, u = probe.getQ().to_numpy(), probe.getU().to_numpy()
    position = {variables.get(i): float(i + 1) for i in range(variables.getSize())}
    if q.size != cs.getSize() or u.size != cs.getSize():
        raise LoperInputError(
            f"{model_source(model)}: {q.size} generalised coordinates and {u.size} speeds for "
            f"{cs.getSize()} coordinates; inverse dynamics needs one of each per coordinate"
        )
    qi, ui = [], []
    for name in names:
        path = cs.get(name).getAbsolutePathString()
        qi.append(int(np.flatnonzero(q == position[f"{path}/value"])[0]))
        ui.append(int(np.flatnonzero(u == position[f"{path}/speed"])[0]))
    return np.array(qi), np.array(ui)


def _scattered(values: np.ndarray, index: np.ndarray) -> list[float]:
    """``values`` (one per coordinate) placed at the state slots ``index``, as a list for ``opensim.Vector``."""
    out = np.empty(values.size)
    out[index] = values
    return out.tolist()


def _is_translational(osim, coordinate) -> bool:
    """Whether a coordinate is a translation (a coupled one by the joint axes it drives)."""
    kind = coordinate.getMotionType()
    if kind != osim.Coordinate.Coupled:
        return kind == osim.Coordinate.Translational
    joint = osim.CustomJoint.safeDownCast(coordinate.getJoint())
    if joint is None:
        return False
    transform, name = joint.getSpatialTransform(), coordinate.getName()
    driven = []
    for k in range(6):
        listed = transform.getTransformAxis(k).getCoordinateNames()
        if any(listed.getValue(i) == name for i in range(listed.size())):
            driven.append(k)
    return bool(driven) and min(driven) >= 3


def _working_copy(osim, model, loads: Sequence[FootLoad], t: np.ndarray):
    """A copy of ``model`` with its own forces off and the loads added; its state and the loads' Storages."""
    work = osim.Model(model)
    forces = work.updForceSet()
    for i in range(forces.getSize()):
        forces.get(i).set_appliesForce(False)
    storages = _add_external_forces(osim, work, loads, float(t[0]), float(t[-1]))
    state = work.initSystem()
    return work, state, storages


def generalized_forces(
    model: opensim.Model,
    time_s: np.ndarray,
    coordinates: pd.DataFrame,
    loads: Sequence[FootLoad] = (),
    *,
    cutoff_hz: float | None,
) -> pd.DataFrame:
    """The generalised forces (joint moments) that make ``model`` follow ``coordinates`` under ``loads``.

    Parameters
    ----------
    model : opensim.Model
        The model; not changed (a copy gets the loads, with the model's own forces switched off).
    time_s : ndarray, shape (n_frames,)
        Frame times (s): finite, strictly increasing, at least 10 frames; equally spaced with a cut-off.
    coordinates : pandas.DataFrame, shape (n_frames, n_coords)
        Coordinate values (rad for rotations, m for translations), one column per coordinate of the model,
        named after it. Coordinates left out stay at their default value (zero speed), as in OpenSim's tool.
    loads : sequence of FootLoad
        The ground's loads on the feet (force N, point m, torque N·m, ground frame); their times must cover
        ``time_s``. Empty: no external load.
    cutoff_hz : float or None
        Cut-off (Hz) of the zero-lag low-pass of the coordinates (OpenSim's ``lowpass_cutoff_frequency``:
        3rd-order Butterworth forward and backward after padding), below half the frame rate; None: no filter.

    Returns
    -------
    pandas.DataFrame, shape (n_frames, 1 + n_model_coords)
        ``time_s`` and, for every coordinate of the model in its coordinate-set order,
        ``<coordinate>_moment_nm`` (N·m, rotational) or ``<coordinate>_force_n`` (N, translational): the
        generalised force acting in the coordinate's positive sense.

    Raises
    ------
    LoperInputError
        A column that is not a coordinate of the model, non-finite coordinates, times not increasing or not
        equally spaced, too few frames, a bad cut-off, a load on a body the model lacks, a load with bad
        shapes or values or not covering the coordinates' times, a model with quaternion coordinates.
    """
    osim = quiet_opensim()
    t, names, values = _coordinate_table(model, time_s, coordinates)
    splines, _filtered = _coordinate_splines(osim, t, names, values, cutoff_hz)
    derivatives = [_spline_derivatives(splines, names, t, order) for order in (0, 1, 2)]
    work, state, _storages = _working_copy(osim, model, loads, t)
    cs = work.getCoordinateSet()
    every = [cs.get(i).getName() for i in range(cs.getSize())]
    qi, ui = _state_indices(osim, work, state, every)
    given = {c: j for j, c in enumerate(names)}
    q0 = np.array([cs.get(c).getDefaultValue() for c in every])
    solver = osim.InverseDynamicsSolver(work)
    out = np.empty((t.size, len(every)))
    for k in range(t.size):
        q, u, udot = q0.copy(), np.zeros(len(every)), np.zeros(len(every))
        for i, c in enumerate(every):
            if c in given:
                q[i], u[i], udot[i] = (d[k, given[c]] for d in derivatives)
        state.setTime(float(t[k]))
        state.setQ(osim.Vector(_scattered(q, qi)))
        state.setU(osim.Vector(_scattered(u, ui)))
        work.realizeVelocity(state)
        residual = solver.solve(state, osim.Vector(_scattered(udot, ui))).to_numpy()
        out[k] = residual[ui]
    columns = {"time_s": t}
    for i, c in enumerate(every):
        columns[c + (_FORCE if _is_translational(osim, cs.get(c)) else _MOMENT)] = out[:, i]
    return pd.DataFrame(columns)


def _check_time(table: pd.DataFrame, name: str) -> np.ndarray:
    """The ``time_s`` column of ``table``, refused if absent."""
    if not isinstance(table, pd.DataFrame) or "time_s" not in table.columns:
        raise LoperInputError(f"{name} must be a DataFrame with a time_s column")
    return table["time_s"].to_numpy(dtype=float)


def joint_powers_w(moments: pd.DataFrame, speeds: pd.DataFrame) -> pd.DataFrame:
    """Power (W) of each generalised force: moment (N·m) × angular speed (rad/s), or force (N) × speed (m/s).

    Parameters
    ----------
    moments : pandas.DataFrame, shape (n_frames, ...)
        ``time_s`` and ``<coordinate>_moment_nm`` / ``<coordinate>_force_n`` columns
        (:func:`generalized_forces`).
    speeds : pandas.DataFrame, shape (n_frames, ...)
        ``time_s`` (the same times) and a ``<coordinate>`` column (rad/s or m/s) for every force of
        ``moments`` (:func:`coordinate_speeds`); other columns are ignored.

    Returns
    -------
    pandas.DataFrame, shape (n_frames, 1 + n_forces)
        ``time_s`` and ``<coordinate>_power_w`` (W) in ``moments``' column order: positive when the joint
        generates energy (force and motion in the same sense).

    Raises
    ------
    LoperInputError
        No ``time_s`` in either table, different times, a force without its speed column.
    """
    t = _check_time(moments, "moments")
    ts = _check_time(speeds, "speeds")
    if t.shape != ts.shape or not np.array_equal(t, ts):
        raise LoperInputError(f"speeds: time_s must equal moments' time_s ({t.size} frames), got {ts.size} frames")
    out = {"time_s": t}
    for column in moments.columns:
        for suffix in (_MOMENT, _FORCE):
            if column.endswith(suffix):
                coordinate = column[: -len(suffix)]
                if coordinate not in speeds.columns:
                    raise LoperInputError(f"speeds: no column '{coordinate}' for moments' '{column}'")
                out[coordinate + _POWER] = moments[column].to_numpy(float) * speeds[coordinate].to_numpy(float)
    return pd.DataFrame(out)


def normalised_per_kg(table: pd.DataFrame, mass_kg: float) -> pd.DataFrame:
    """``table``'s moments, forces and powers divided by the body mass, with ``_per_kg`` added to their names.

    Parameters
    ----------
    table : pandas.DataFrame
        ``time_s`` and columns ending in ``_moment_nm``, ``_force_n`` or ``_power_w``
        (:func:`generalized_forces`, :func:`joint_powers_w`); other columns are kept as they are.
    mass_kg : float
        Body mass (kg), finite and > 0.

    Returns
    -------
    pandas.DataFrame
        Same rows; ``<name>_moment_nm_per_kg`` (N·m/kg), ``<name>_force_n_per_kg`` (N/kg),
        ``<name>_power_w_per_kg`` (W/kg).

    Raises
    ------
    LoperInputError
        ``mass_kg`` not a positive number, ``table`` without ``time_s``.
    """
    mass = positive("mass_kg", mass_kg)
    _check_time(table, "table")
    out = {}
    for column in table.columns:
        if column.endswith((_MOMENT, _FORCE, _POWER)):
            out[f"{column}_per_kg"] = table[column].to_numpy(float) / mass
        else:
            out[column] = table[column].to_numpy()
    return pd.DataFrame(out)
