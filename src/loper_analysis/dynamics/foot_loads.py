"""The ground's load on each foot from the force plates and the contacts, and the times it is known.

Inputs are tables in memory: the ground reactions of a trial (the columns of the ``grf`` step's external-loads
``.mot``: ``time_s`` or ``time``, then per plate n ``{n}_ground_force_v{x,y,z}`` N, ``{n}_ground_force_p{x,y,z}``
m, ``{n}_ground_torque_{x,y,z}`` N·m, in the model's frame, Y up) and the contacts of the ``events`` step
(``plate``, ``side``, ``flag``, ``start_s``, ``end_s`` and, when a foot stands on several plates at once,
``foot_contact``).

A foot's load (:func:`foot_loads`)
    A foot contact is the contact rows that share a ``foot_contact`` (each row its own without the column); it
    counts for a side when every row of it is ``ok`` and of that side. Plate i's load enters the foot's sum over
    the samples its row covers (``start_s`` .. ``end_s``, widened to the plate's unbroken run of non-zero force
    around it, so the few samples between the ``grf`` step's and the ``events`` step's thresholds are not
    lost), and is zero elsewhere. With several plates loaded at once the forces add, the point is the
    force-weighted centre of pressure ``p = sum(w_i p_i) / sum(w_i)`` with ``w_i`` the vertical (+Y) force of
    plate i, and the free torques move to it exactly: ``T = sum(T_i + (p_i - p) x F_i)``, so that force and
    moment about any point equal the plates' sums. Where the foot is unloaded the force and the torque are 0 and
    the point is held at the nearest loaded sample's (the earlier on a tie), as the ``grf`` step holds a plate's
    centre of pressure, so an interpolated point never jumps.

Valid times (:func:`valid_intervals`)
    A leg's joint moments are right only while its foot's load is known: the moments of a tree's joint depend
    on the loads distal to it only. The foot's load is known

    * during its counted (``ok``) foot contacts, ``start_s`` .. ``end_s`` (the plates measure all of it), and
    * in its swing, from a known toe-off (the end of a counted contact) to its next heel strike (the start of
      the next counted contact of that foot), where the load is zero. The heel strike must be the foot's next
      touch-down: no contact of that foot that is not counted and no contact without a foot starts before it
      (the foot may have landed there), and the other foot neither lands nor lifts off in between (walking
      has no flight phase: from this foot's toe-off to its next heel strike the other foot stands; a toe-off
      or a heel strike of the other foot in between means this foot landed unseen, out of the plates). The
      swing is then valid until the earlier of its next heel strike and the other foot's next toe-off, which
      in walking is the heel strike. A swing whose next heel strike is unknown (the foot lands off the plates,
      or the trial ends) is not valid: the foot lands before the other foot's next toe-off, but at an unknown
      time.

    Nothing before a side's first counted contact is valid (its previous toe-off is unknown). The rule takes
    the events as they are: no threshold, no duration.

Every bad input raises :class:`~loper_analysis.errors.LoperInputError` naming the input and the value.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pandas as pd

from loper_analysis.constants import SIDES
from loper_analysis.dynamics.inverse_dynamics import FootLoad
from loper_analysis.errors import LoperInputError

__all__ = [
    "CONTACT_COLUMNS",
    "FOOT_BODIES",
    "combine_plate_loads",
    "counted_contacts",
    "foot_loads",
    "valid_intervals",
    "valid_mask",
]

#: The foot body of each side in OpenSim's gait models (gait2392, Rajagopal2016).
FOOT_BODIES: dict[str, str] = {"left": "calcn_l", "right": "calcn_r"}
#: Columns a contact table needs (``foot_contact`` is optional).
CONTACT_COLUMNS: tuple[str, ...] = ("plate", "side", "flag", "start_s", "end_s")
#: Index of the model's vertical axis (OpenSim: Y up).
_UP = 1
_OK = "ok"


def _grf_time(grf: pd.DataFrame) -> np.ndarray:
    """The time column (s) of a ground-reaction table, checked finite and strictly increasing."""
    if not isinstance(grf, pd.DataFrame):
        raise LoperInputError(f"grf must be a pandas DataFrame, got {type(grf).__name__}")
    name = "time_s" if "time_s" in grf.columns else "time" if "time" in grf.columns else None
    if name is None:
        raise LoperInputError("grf: no time_s (or time) column")
    t = grf[name].to_numpy(dtype=float)
    if t.size < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise LoperInputError(f"grf: {name} must hold at least 2 finite, strictly increasing times")
    return t


def _plate_columns(n: int) -> list[str]:
    """The nine columns of plate ``n``: force (N), point (m), torque (N·m), x y z each."""
    return [f"{n}_ground_{kind}{a}" for kind in ("force_v", "force_p", "torque_") for a in "xyz"]


def _plate_arrays(grf: pd.DataFrame, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force (N), point (m) and torque (N·m) of plate ``n``, each (n_samples, 3), checked finite."""
    columns = _plate_columns(n)
    missing = [c for c in columns if c not in grf.columns]
    if missing:
        raise LoperInputError(f"grf: plate {n} lacks column(s) {missing}")
    values = grf[columns].to_numpy(dtype=float)
    bad = np.argwhere(~np.isfinite(values))
    if bad.size:
        raise LoperInputError(f"grf: '{columns[bad[0][1]]}' is not finite at row {bad[0][0]}")
    return values[:, 0:3], values[:, 3:6], values[:, 6:9]


def _check_contacts(contacts: pd.DataFrame) -> pd.DataFrame:
    """The contact table with a ``foot_contact`` column (each row its own when absent) and text sides/flags."""
    if not isinstance(contacts, pd.DataFrame):
        raise LoperInputError(f"contacts must be a pandas DataFrame, got {type(contacts).__name__}")
    missing = [c for c in CONTACT_COLUMNS if c not in contacts.columns]
    if missing:
        raise LoperInputError(f"contacts: missing column(s) {missing}")
    out = contacts.reset_index(drop=True).copy()
    out["side"] = out["side"].fillna("").astype(str)
    out["flag"] = out["flag"].fillna("").astype(str)
    if "foot_contact" not in out.columns:
        out["foot_contact"] = np.arange(len(out))
    bounds = out[["start_s", "end_s"]].to_numpy(dtype=float)
    bad = np.flatnonzero(~(np.isfinite(bounds).all(axis=1) & (bounds[:, 0] < bounds[:, 1])))
    if bad.size:
        r = bad[0]
        raise LoperInputError(f"contacts: row {r} needs finite start_s < end_s, got {bounds[r, 0]} .. {bounds[r, 1]}")
    return out


def counted_contacts(contacts: pd.DataFrame, side: str) -> pd.DataFrame:
    """The foot contacts of ``side`` whose loads are known: every row of the foot contact ``ok`` and of ``side``.

    Parameters
    ----------
    contacts : pandas.DataFrame
        The ``events`` step's contact table (:data:`CONTACT_COLUMNS`, optional ``foot_contact``).
    side : str
        ``left`` or ``right``.

    Returns
    -------
    pandas.DataFrame
        The rows of the counted foot contacts (same columns, ``foot_contact`` filled), by start time.
    """
    table = _check_contacts(contacts)
    row_ok = (table["flag"] == _OK) & (table["side"] == side)
    bad_feet = set(table.loc[~row_ok, "foot_contact"])
    keep = row_ok & ~table["foot_contact"].isin(bad_feet)
    return table[keep].sort_values("start_s", kind="stable").reset_index(drop=True)


def _loaded_run(t: np.ndarray, loaded: np.ndarray, start_s: float, end_s: float) -> np.ndarray:
    """Samples (bool, shape (n,)) from ``start_s`` to ``end_s`` widened to the unbroken run of ``loaded`` around."""
    inside = (t >= start_s) & (t <= end_s)
    idx = np.flatnonzero(inside)
    if idx.size == 0:
        return inside
    first, last = idx[0], idx[-1]
    while first > 0 and loaded[first - 1]:
        first -= 1
    while last < t.size - 1 and loaded[last + 1]:
        last += 1
    out = np.zeros(t.size, dtype=bool)
    out[first : last + 1] = True
    return out


def _held(values: np.ndarray, known: np.ndarray) -> np.ndarray:
    """``values`` (n, 3) with the rows not ``known`` replaced by the nearest known row's (earlier on a tie)."""
    idx = np.flatnonzero(known)
    if idx.size == 0 or idx.size == known.size:
        return values
    n = known.size
    pos = np.searchsorted(idx, np.arange(n))
    before = idx[np.clip(pos - 1, 0, idx.size - 1)]
    after = idx[np.clip(pos, 0, idx.size - 1)]
    rows = np.arange(n)
    nearest = np.where(np.abs(rows - before) <= np.abs(after - rows), before, after)
    out = values.copy()
    out[~known] = values[nearest[~known]]
    return out


def combine_plate_loads(
    forces_n: np.ndarray, points_m: np.ndarray, torques_nm: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One load equivalent to several plates' loads on one foot: forces added, the point the vertical-force
    weighted centre of pressure, the free torques moved to it exactly.

    Parameters
    ----------
    forces_n, points_m, torques_nm : ndarray, shape (k, n, 3)
        Force (N), point of application (m) and free torque (N·m) of k plates over n samples, one frame (Y up).

    Returns
    -------
    force_n, point_m, torque_nm : ndarray, shape (n, 3)
        ``F = sum F_i``; ``p = sum(w_i p_i) / sum(w_i)``, ``w_i`` plate i's vertical force where positive (a
        sample without vertical force takes the nearest loaded sample's point, or the plates' mean point when no
        sample is loaded); ``T = sum(T_i + (p_i - p) x F_i)``. Force and moment about any point equal the
        plates' sums.
    """
    f = np.asarray(forces_n, dtype=float)
    p = np.asarray(points_m, dtype=float)
    tq = np.asarray(torques_nm, dtype=float)
    if f.ndim != 3 or f.shape[-1] != 3 or p.shape != f.shape or tq.shape != f.shape:
        raise LoperInputError(f"plate loads must share a shape (k, n, 3), got {f.shape}, {p.shape}, {tq.shape}")
    w = np.clip(f[:, :, _UP], 0.0, None)
    total = w.sum(axis=0)
    loaded = total > 0
    point = p.mean(axis=0)
    point[loaded] = (w[:, loaded, None] * p[:, loaded]).sum(axis=0) / total[loaded, None]
    point = _held(point, loaded)
    force = f.sum(axis=0)
    torque = (tq + np.cross(p - point[None], f)).sum(axis=0)
    return force, point, torque


def _side_load(grf: pd.DataFrame, t: np.ndarray, rows: pd.DataFrame) -> tuple[np.ndarray, ...]:
    """Force, point and torque (n, 3) of one foot over its counted contact rows."""
    forces, points, torques = [], [], []
    for plate, group in rows.groupby("plate"):
        f, p, tq = _plate_arrays(grf, int(plate))
        loaded = np.any(f != 0.0, axis=1)
        mask = np.zeros(t.size, dtype=bool)
        for start, end in group[["start_s", "end_s"]].to_numpy(dtype=float):
            mask |= _loaded_run(t, loaded, start, end)
        forces.append(np.where(mask[:, None], f, 0.0))
        torques.append(np.where(mask[:, None], tq, 0.0))
        points.append(p)
    if not forces:
        zero = np.zeros((t.size, 3))
        return zero, zero.copy(), zero.copy()
    return combine_plate_loads(np.array(forces), np.array(points), np.array(torques))


def foot_loads(
    grf: pd.DataFrame, contacts: pd.DataFrame, bodies: Mapping[str, str] = FOOT_BODIES
) -> dict[str, FootLoad]:
    """Each foot's load: the sum of its plates' loads over its counted (``ok``) contacts, zero elsewhere.

    Parameters
    ----------
    grf : pandas.DataFrame, shape (n_samples, 1 + 9 n_plates)
        ``time_s`` (or ``time``, s) and the plates' ``{n}_ground_force_v*`` (N), ``{n}_ground_force_p*`` (m),
        ``{n}_ground_torque_*`` (N·m) columns, model frame (Y up).
    contacts : pandas.DataFrame
        The ``events`` step's contacts (:data:`CONTACT_COLUMNS`, optional ``foot_contact``; s).
    bodies : mapping of str to str
        Side (``left``, ``right``) -> the model body the foot's load acts on.

    Returns
    -------
    dict of str to FootLoad
        One :class:`FootLoad` per side of ``bodies`` on the ground reactions' times (n_samples,): force (N),
        point (m) and free torque (N·m), ground frame (see the module docstring for the combination).

    Raises
    ------
    LoperInputError
        A bad table, an unknown side, a counted contact on a plate the ground reactions lack.
    """
    t = _grf_time(grf)
    out = {}
    for side, body in bodies.items():
        if side not in SIDES:
            raise LoperInputError(f"bodies: side must be one of {SIDES}, got {side!r}")
        rows = counted_contacts(contacts, side)
        force, point, torque = _side_load(grf, t, rows)
        out[side] = FootLoad(body=str(body), time_s=t, force_n=force, point_m=point, torque_nm=torque)
    return out


def _next_after(times: np.ndarray, after: float) -> float:
    """The first of ``times`` strictly after ``after`` (inf if none)."""
    later = times[times > after]
    return float(later.min()) if later.size else np.inf


def valid_intervals(contacts: pd.DataFrame, side: str) -> np.ndarray:
    """The intervals (s) in which the load on ``side``'s foot is known (module docstring: the rule).

    Parameters
    ----------
    contacts : pandas.DataFrame
        The ``events`` step's contacts (:data:`CONTACT_COLUMNS`, optional ``foot_contact``; s).
    side : str
        ``left`` or ``right``.

    Returns
    -------
    ndarray, shape (k, 2)
        Start and end (s) of the disjoint valid intervals, in time order (touching ones merged); (0, 2) when
        the side has no counted contact.
    """
    if side not in SIDES:
        raise LoperInputError(f"side must be one of {SIDES}, got {side!r}")
    table = _check_contacts(contacts)
    other = next(s for s in SIDES if s != side)
    counted = counted_contacts(table, side)
    feet = counted.groupby("foot_contact").agg(start_s=("start_s", "min"), end_s=("end_s", "max"))
    feet = feet.sort_values("start_s").to_numpy(dtype=float)
    ids = set(counted["foot_contact"])
    mine_or_unknown = table[(table["side"].isin([side, ""])) & ~table["foot_contact"].isin(ids)]
    landings = np.concatenate([feet[:, 0], mine_or_unknown["start_s"].to_numpy(dtype=float)])
    others = table[table["side"] == other]
    other_events = others[["start_s", "end_s"]].to_numpy(dtype=float).ravel()
    other_toe_offs = others["end_s"].to_numpy(dtype=float)
    spans = [tuple(row) for row in feet]
    for toe_off in feet[:, 1]:
        heel_strike = _next_after(landings, toe_off)
        known = np.isfinite(heel_strike) and np.isin(heel_strike, feet[:, 0])
        seen = other_events[(other_events > toe_off) & (other_events < heel_strike)]
        if known and seen.size == 0 and _next_after(other_toe_offs, toe_off) >= heel_strike:
            spans.append((toe_off, heel_strike))
    return _merged(spans)


def _merged(spans: list[tuple[float, float]]) -> np.ndarray:
    """Intervals (k, 2) sorted and merged where they touch or overlap."""
    out: list[list[float]] = []
    for start, end in sorted(spans):
        if out and start <= out[-1][1]:
            out[-1][1] = max(out[-1][1], end)
        else:
            out.append([start, end])
    return np.array(out, dtype=float).reshape(-1, 2)


def valid_mask(time_s: np.ndarray, intervals: np.ndarray) -> np.ndarray:
    """Whether each time (s, shape (n,)) lies in one of the closed ``intervals`` (k, 2): bool, shape (n,)."""
    t = np.asarray(time_s, dtype=float)
    iv = np.asarray(intervals, dtype=float).reshape(-1, 2)
    return ((t[:, None] >= iv[None, :, 0]) & (t[:, None] <= iv[None, :, 1])).any(axis=1)
