"""Hip, knee and ankle moments and powers of each leg, in the sense of our angles, and per gait cycle.

:func:`leg_moments` turns the generalised forces of a model (:func:`~loper_analysis.dynamics.inverse_dynamics.
generalized_forces`) and the speeds of its coordinates into our joints' moments and powers: for the joint
``<joint>_<side>`` of the coordinate map (``hip_left`` -> ``hip_flexion_l``, sign 1; gait2392's
``knee_left`` -> ``knee_angle_l``, sign -1) the moment is ``sign`` × the coordinate's generalised force, so it is
positive in the sense of our angle (hip flexion, knee flexion, ankle dorsiflexion), and the power is the
coordinate's moment × its speed, which the sign leaves unchanged (``(s M)(s ω) = M ω``): positive when the joint
generates energy. Per kg: divided by the body mass.

:func:`joint_cycles` cuts the moments into the strides of a stride table (heel strike to the next heel strike of
one side, not removed) that lie wholly in that side's valid times (:func:`~loper_analysis.dynamics.foot_loads.
valid_intervals`) and resamples each onto ``n_points`` equally spaced points of the cycle (0 .. 100 %,
linear interpolation, :func:`loper_analysis.gait.resampling.cut`). :func:`cycle_summary` gives the mean and the
sample SD (ddof 1) across strides per side, joint and point.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import cut

__all__ = [
    "CYCLE_COLUMNS",
    "SUMMARY_COLUMNS",
    "N_POINTS",
    "cycle_summary",
    "joint_coordinates",
    "joint_cycles",
    "leg_moments",
    "moment_columns",
]

#: Points per normalised cycle (0 .. 100 % in steps of 1 %).
N_POINTS = 101
#: Columns of :func:`joint_cycles` (units in the names; ``percent_cycle`` in %).
CYCLE_COLUMNS: tuple[str, ...] = (
    "stride",
    "side",
    "joint",
    "percent_cycle",
    "moment_nm",
    "moment_nm_per_kg",
    "power_w_per_kg",
)
#: Columns of :func:`cycle_summary`.
SUMMARY_COLUMNS: tuple[str, ...] = (
    "side",
    "joint",
    "percent_cycle",
    "n_strides",
    "moment_nm_mean",
    "moment_nm_sd",
    "moment_nm_per_kg_mean",
    "moment_nm_per_kg_sd",
    "power_w_per_kg_mean",
    "power_w_per_kg_sd",
)
_QUANTITIES = ("moment_nm", "moment_nm_per_kg", "power_w_per_kg")


def moment_columns(side: str, joint: str) -> dict[str, str]:
    """The time-series columns of one joint: quantity (:data:`CYCLE_COLUMNS`' last three) -> column name."""
    return {q: f"{joint}_{side}_{q}" for q in _QUANTITIES}


def joint_coordinates(coordinate_map: Mapping) -> dict[tuple[str, str], tuple[str, float]]:
    """(side, joint) -> (model coordinate, sign ±1) of the coordinate map's ``<joint>_<side>`` entries.

    ``coordinate_map`` maps our angle names to ``(coordinate, sign)`` or ``{"coordinate": name, "sign": ±1}``
    (``ik.coordinate_map``; :data:`loper_analysis.motion.ik.DEFAULT_COORDINATE_MAP`). Joints it leaves out
    are left out.
    """
    out = {}
    for side in SIDES:
        for joint in JOINTS:
            entry = coordinate_map.get(f"{joint}_{side}")
            if entry is None:
                continue
            name, sign = (entry["coordinate"], entry["sign"]) if isinstance(entry, Mapping) else entry
            if float(sign) not in (1.0, -1.0):
                raise LoperInputError(f"coordinate map, key {joint}_{side}: sign must be 1 or -1, got {sign!r}")
            out[(side, joint)] = (str(name), float(sign))
    return out


def leg_moments(
    forces: pd.DataFrame,
    speeds: pd.DataFrame,
    coordinate_map: Mapping,
    mass_kg: float,
    valid: Mapping[str, np.ndarray] | None = None,
) -> pd.DataFrame:
    """Our joints' moments (N·m, N·m/kg) and powers (W/kg), signed as our angles, over time.

    Parameters
    ----------
    forces : pandas.DataFrame, shape (n_frames, ...)
        ``time_s`` (s) and ``<coordinate>_moment_nm`` (N·m) columns
        (:func:`~loper_analysis.dynamics.inverse_dynamics.generalized_forces`).
    speeds : pandas.DataFrame, shape (n_frames, ...)
        ``time_s`` (the same) and one column per mapped coordinate (rad/s)
        (:func:`~loper_analysis.dynamics.inverse_dynamics.coordinate_speeds`).
    coordinate_map : mapping
        Our angles -> model coordinate and sign (:func:`joint_coordinates`).
    mass_kg : float
        Body mass (kg), > 0.
    valid : mapping of str to ndarray of bool, shape (n_frames,), optional
        Side -> whether its foot's load is known at each frame; written as ``valid_<side>`` columns.

    Returns
    -------
    pandas.DataFrame, shape (n_frames, ...)
        ``time_s``, then per side and joint ``<joint>_<side>_moment_nm`` (N·m), ``..._moment_nm_per_kg``
        (N·m/kg), ``..._power_w_per_kg`` (W/kg), then ``valid_<side>`` (bool) when given.
    """
    if not (np.isfinite(mass_kg) and mass_kg > 0):
        raise LoperInputError(f"mass_kg must be a positive number, got {mass_kg!r}")
    t = forces["time_s"].to_numpy(dtype=float)
    if not np.array_equal(t, speeds["time_s"].to_numpy(dtype=float)):
        raise LoperInputError("speeds: time_s must equal the forces' time_s")
    out: dict[str, np.ndarray] = {"time_s": t}
    for (side, joint), (coordinate, sign) in joint_coordinates(coordinate_map).items():
        column = f"{coordinate}_moment_nm"
        if column not in forces.columns or coordinate not in speeds.columns:
            raise LoperInputError(f"coordinate map, key {joint}_{side}: no moment or speed of '{coordinate}'")
        moment = forces[column].to_numpy(dtype=float)
        speed = speeds[coordinate].to_numpy(dtype=float)
        names = moment_columns(side, joint)
        out[names["moment_nm"]] = sign * moment
        out[names["moment_nm_per_kg"]] = sign * moment / mass_kg
        out[names["power_w_per_kg"]] = moment * speed / mass_kg
    for side, mask in (valid or {}).items():
        m = np.asarray(mask, dtype=bool)
        if m.shape != t.shape:
            raise LoperInputError(f"valid[{side!r}] must have shape {t.shape}, got {m.shape}")
        out[f"valid_{side}"] = m
    return pd.DataFrame(out)


def _usable_strides(
    strides: pd.DataFrame, side: str, intervals: np.ndarray, t_first: float, t_last: float
) -> pd.DataFrame:
    """The strides of ``side`` not removed whose heel strike .. end lies in one valid interval and the frames."""
    rows = strides[strides["side"] == side]
    if "removed" in rows.columns:
        removed = rows["removed"].astype(str).str.lower().isin(["true", "1"])
        rows = rows[~removed.to_numpy()]
    start = rows["heel_strike_s"].to_numpy(dtype=float)
    end = rows["end_s"].to_numpy(dtype=float)
    iv = np.asarray(intervals, dtype=float).reshape(-1, 2)
    inside = ((start[:, None] >= iv[None, :, 0]) & (end[:, None] <= iv[None, :, 1])).any(axis=1)
    inside &= (start >= t_first) & (end <= t_last) & (start < end)
    return rows[inside]


def joint_cycles(
    moments: pd.DataFrame,
    strides: pd.DataFrame,
    intervals: Mapping[str, np.ndarray],
    n_points: int = N_POINTS,
) -> pd.DataFrame:
    """The moments and powers of each usable stride, time-normalised to the gait cycle, as a tidy table.

    Parameters
    ----------
    moments : pandas.DataFrame, shape (n_frames, ...)
        :func:`leg_moments`' table (``time_s`` s, ``<joint>_<side>_<quantity>`` columns).
    strides : pandas.DataFrame
        The ``strides`` step's table: ``stride``, ``side``, ``heel_strike_s``, ``end_s`` (s), optional
        ``removed``.
    intervals : mapping of str to ndarray, shape (k, 2)
        Side -> its valid intervals (s) (:func:`~loper_analysis.dynamics.foot_loads.valid_intervals`).
    n_points : int
        Points per cycle (>= 2): 0 .. 100 % of the cycle from heel strike to the next heel strike.

    Returns
    -------
    pandas.DataFrame, shape (n_strides × n_joints × n_points, 7)
        :data:`CYCLE_COLUMNS`: ``stride``, ``side``, ``joint``, ``percent_cycle`` (%), ``moment_nm`` (N·m),
        ``moment_nm_per_kg`` (N·m/kg), ``power_w_per_kg`` (W/kg); empty (those columns) without a usable stride.
    """
    missing = [c for c in ("stride", "side", "heel_strike_s", "end_s") if c not in strides.columns]
    if missing:
        raise LoperInputError(f"strides: missing column(s) {missing}")
    t = moments["time_s"].to_numpy(dtype=float)
    percent = np.linspace(0.0, 100.0, int(n_points))
    parts = []
    for side, side_intervals in intervals.items():
        rows = _usable_strides(strides, side, side_intervals, float(t[0]), float(t[-1]))
        for joint in JOINTS:
            names = moment_columns(side, joint)
            if rows.empty or names["moment_nm"] not in moments.columns:
                continue
            values = moments[[names[q] for q in _QUANTITIES]].to_numpy(dtype=float)
            cycles = cut(t, values, rows["heel_strike_s"], rows["end_s"], int(n_points), f"{side} {joint}")
            for stride, cycle in zip(rows["stride"].to_numpy(), cycles, strict=True):
                part = {"stride": stride, "side": side, "joint": joint, "percent_cycle": percent}
                part.update({q: cycle[:, k] for k, q in enumerate(_QUANTITIES)})
                parts.append(pd.DataFrame(part))
    if not parts:
        return pd.DataFrame({c: pd.Series(dtype=float if c not in ("side", "joint") else str) for c in CYCLE_COLUMNS})
    return pd.concat(parts, ignore_index=True)[list(CYCLE_COLUMNS)]


def cycle_summary(cycles: pd.DataFrame) -> pd.DataFrame:
    """Mean and SD (ddof 1; NaN for one stride) across strides of :func:`joint_cycles`' table.

    Parameters
    ----------
    cycles : pandas.DataFrame
        :data:`CYCLE_COLUMNS`.

    Returns
    -------
    pandas.DataFrame
        :data:`SUMMARY_COLUMNS`: per side, joint and ``percent_cycle`` (%) the number of strides and the mean
        and SD of the moment (N·m), the moment per kg (N·m/kg) and the power per kg (W/kg).
    """
    keys = ["side", "joint", "percent_cycle"]
    if cycles.empty:
        return pd.DataFrame({c: pd.Series(dtype=str if c in ("side", "joint") else float) for c in SUMMARY_COLUMNS})
    grouped = cycles.groupby(keys, sort=False)
    out = grouped["stride"].nunique().rename("n_strides").reset_index()
    for q in _QUANTITIES:
        out[f"{q}_mean"] = grouped[q].mean().to_numpy()
        out[f"{q}_sd"] = grouped[q].std(ddof=1).to_numpy()
    return out[list(SUMMARY_COLUMNS)]
