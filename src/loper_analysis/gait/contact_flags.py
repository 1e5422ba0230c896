"""The verdict on one force-plate contact: the foot that made it, its flag and the reason in words.

* :class:`ContactScene` - what the contacts of a trial are judged against: the heel (and toe) markers, the
  plates' corners and the settings of :func:`loper_analysis.gait.contacts.foot_contacts`;
* :func:`heel_offsets` - each heel's distance outside a plate and height above it over a contact's window;
* :func:`contact_verdict` - the foot on a contact (the heel on the plate at the start probe, or the nearest
  low heel off its edge), its flag (:data:`loper_analysis.constants.CONTACT_FLAGS`: ``incomplete``,
  ``heel_missing``, ``two_feet``, ``no_foot``, ``off_plate``, ``wrong_belt`` or ``ok``) and, when flagged,
  why the contact gives no events, in words;
* :func:`on_plate`, :func:`positions_at` - whether heels are on a plate; marker positions between frames.

Time in s, positions in m (markers and plate corners in one frame). ``docs/events.md`` explains the rules.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import NamedTuple

import numpy as np

from loper_analysis.constants import SIDES
from loper_analysis.gait.plate_geometry import plate_axes, plate_offsets

__all__ = [
    "ContactScene",
    "Verdict",
    "contact_verdict",
    "first_load",
    "heel_landing",
    "heel_offsets",
    "load_stays_under",
    "on_plate",
    "positions_at",
]


class ContactScene(NamedTuple):
    """What the contacts of a trial are judged against (:func:`loper_analysis.gait.contacts.foot_contacts`).

    ``marker_time_s`` (n_frames,) in s; ``heels_m``, ``toes_m`` (or None): ``{side: (n_frames, 3)}`` in m;
    ``corners_m``: per plate its corners (4, 3) in m, ``numbers`` its number; ``vertical_axis`` and ``up``: the
    vertical; the checked probe delay and dwell time (s), margin, reach and highest heel (m); ``plates``: per
    plate its :class:`loper_analysis.gait.contacts.PlateForce` (its ``cop_m`` lets the force decide a heel off the
    edge and a second foot, :func:`first_load`, :func:`load_stays_under`), and ``threshold_on_n`` (N): the force
    above which its centre of pressure is used.
    """

    marker_time_s: np.ndarray
    heels_m: dict[str, np.ndarray]
    toes_m: dict[str, np.ndarray] | None
    corners_m: list[np.ndarray]
    numbers: list[int]
    vertical_axis: int | None
    up: Sequence[float] | None
    delay_s: float
    dwell_s: float
    margin_m: float
    reach_m: float
    max_height_m: float
    plates: Sequence = ()
    threshold_on_n: float = 50.0


def positions_at(time_s: np.ndarray, xyz: np.ndarray, when: np.ndarray) -> np.ndarray:
    """Positions (k, 3) at the times ``when`` (k,), linear between frames; NaN outside the frames or next to a gap."""
    when = np.asarray(when, dtype=float)
    j = np.clip(np.searchsorted(time_s, when, side="right") - 1, 0, time_s.size - 2)
    w = ((when - time_s[j]) / (time_s[j + 1] - time_s[j]))[:, None]
    out = np.where(w == 0.0, xyz[j], (1.0 - w) * xyz[j] + w * xyz[j + 1])  # a frame time needs only its frame
    out[(when < time_s[0]) | (when > time_s[-1])] = np.nan
    return out


def _longest_run_s(times: np.ndarray, mask: np.ndarray) -> float:
    """Longest time span (s) of consecutive True samples; -inf without any."""
    if not mask.any():
        return -np.inf
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return float(np.max(times[last] - times[first]))


def _standing_run(times: np.ndarray, on: np.ndarray, above: np.ndarray, max_height_m: float) -> tuple[float, float]:
    """Longest unbroken stay (start, end in s) of a heel on a plate, leaving out the stays that end with the heel
    still low but off the plate: a swing heel passing low over the plate and coming down beside its edge.

    ``times`` (s), ``on`` (bool) and ``above`` (m above the surface) per sample of the window; (nan, nan) without
    any stay.
    """
    edges = np.diff(np.concatenate([[0], on.astype(np.int8), [0]]))
    first, last = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    best = (np.nan, np.nan)
    for a, b in zip(first, last):
        if b + 1 < on.size and above[b + 1] <= max_height_m:  # left the outline, not the ground: it lands off it
            continue
        if not times[b] - times[a] <= best[1] - best[0]:
            best = (float(times[a]), float(times[b]))
    return best


def on_plate(scene: ContactScene, outside: np.ndarray, above: np.ndarray) -> np.ndarray:
    """Whether heels at ``outside`` (m outside the outline) and ``above`` (m above the surface) are on the plate."""
    return (outside <= scene.margin_m) & (above <= scene.max_height_m)  # NaN: False


def heel_offsets(scene: ContactScene, k: int, times: np.ndarray) -> dict[str, dict]:
    """Per side the heel over plate ``k`` at the window's ``times`` (s).

    ``window``: ``(outside, above)`` (m, each (n_times,)); ``start_on``: on the plate at the start probe;
    ``missing`` (n_times,): NaN heel; ``on_all`` (n_plates,): on each plate at the start probe; ``elsewhere``
    (n_times,): inside another plate's outline, outside this one's (it stands on that plate).
    """
    start_on, on_all, missing, window, elsewhere = {}, {}, {}, {}, {}
    for s in SIDES:
        xyz = positions_at(scene.marker_time_s, scene.heels_m[s], times)
        out, above = plate_offsets(xyz, scene.corners_m[k], scene.vertical_axis, up=scene.up)
        window[s] = (out, above)
        start_on[s] = on_plate(scene, out[:1], above[:1])[0]
        missing[s] = np.isnan(out)
        # on every plate at the start probe: (n_plates,) outside, height
        on_all[s] = np.array(
            [
                on_plate(scene, *plate_offsets(xyz[:1], cc, scene.vertical_axis, up=scene.up))[0]
                for cc in scene.corners_m
            ]
        )
        inside = np.zeros(out.shape, dtype=bool)
        for j, cc in enumerate(scene.corners_m):
            if j != k:
                inside |= plate_offsets(xyz, cc, scene.vertical_axis, up=scene.up)[0] == 0
        elsewhere[s] = inside & (out > 0)
    return {"window": window, "start_on": start_on, "missing": missing, "on_all": on_all, "elsewhere": elsewhere}


def _plane(scene: ContactScene, k: int):
    """A function giving points' (..., 3) coordinates (m) in plate ``k``'s plane (..., 2)."""
    centre, axes = plate_axes(scene.corners_m[k], scene.vertical_axis, "", scene.up)
    return lambda xyz: (np.asarray(xyz, dtype=float) - centre) @ axes[:2].T


def _loaded_cop(scene: ContactScene, k: int, t0: float, t1: float) -> tuple[np.ndarray, ...] | None:
    """Times (s, (n,)), centre of pressure (m, (n, 3)) and force (N, (n,)) of plate ``k``'s samples in
    ``[t0, t1]`` loaded at or above ``scene.threshold_on_n``; None when the plate has no centre of pressure."""
    cop = getattr(scene.plates[k], "cop_m", None) if len(scene.plates) > k else None
    if cop is None:
        return None
    plate = scene.plates[k]
    t, f = np.asarray(plate.time_s, dtype=float), np.asarray(plate.vertical_force_n, dtype=float)
    cop = np.asarray(cop, dtype=float)
    use = (t >= t0) & (t <= t1) & (f >= scene.threshold_on_n) & np.isfinite(cop).all(axis=1)
    return t[use], cop[use], f[use]


def first_load(scene: ContactScene, k: int, start_s: float) -> tuple[float, float, np.ndarray] | None:
    """Where plate ``k`` takes its first load: the force-weighted mean centre of pressure (m, (3,)) over its
    samples at or above the on-threshold from the contact's start ``start_s`` (s) for one marker frame
    interval, with that span's first and last time (s); None without a centre of pressure."""
    frame = float(np.median(np.diff(scene.marker_time_s)))
    loads = _loaded_cop(scene, k, start_s, start_s + frame)
    if loads is None or not loads[0].size:
        return None
    t, cop, f = loads
    return float(t[0]), float(t[-1]), (f[:, None] * cop).sum(axis=0) / f.sum()


def heel_landing(scene: ContactScene, k: int, start_s: float, side: str) -> dict | None:
    """Whether the heel of ``side`` took plate ``k``'s first load (:func:`first_load`): the nearest of the four
    foot markers (both heels and toes, in the plate's plane, at the first load's time) to its centre of pressure
    is that heel. None without a centre of pressure or toe markers.

    Returns ``on`` (bool), ``from_s``, ``to_s`` (the first load's span, s), ``heel_m``, ``toe_m`` (the
    distances of that foot's heel and toe markers, m) and ``nearest`` (the nearest marker, e.g. "left toe").
    """
    first = first_load(scene, k, start_s)
    if first is None or scene.toes_m is None:
        return None
    t0, t1, cop = first
    flat = _plane(scene, k)
    dist = {}
    for s in SIDES:
        for part, markers in (("heel", scene.heels_m), ("toe", scene.toes_m)):
            xyz = positions_at(scene.marker_time_s, markers[s], np.array([t0]))[0]
            dist[f"{s} {part}"] = float(np.linalg.norm(flat(xyz) - flat(cop)))
    seen = {name: d for name, d in dist.items() if np.isfinite(d)}
    nearest = min(seen, key=seen.get) if seen else ""
    return {
        "on": nearest == f"{side} heel",
        "from_s": t0,
        "to_s": t1,
        "heel_m": dist[f"{side} heel"],
        "toe_m": dist[f"{side} toe"],
        "nearest": nearest,
    }


def _foot_distance(scene: ContactScene, flat, side: str, t: np.ndarray, cop: np.ndarray) -> np.ndarray:
    """Distance (m, (n,)) in the plate's plane from the centre of pressure ``cop`` (n, 3) at ``t`` (s) to the
    foot of ``side``: its heel-toe segment (its heel without toe markers); NaN where a marker is missing."""
    heel = flat(positions_at(scene.marker_time_s, scene.heels_m[side], t))
    toe = heel if scene.toes_m is None else flat(positions_at(scene.marker_time_s, scene.toes_m[side], t))
    c, along = flat(cop), toe - heel
    length2 = np.sum(along * along, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        w = np.clip(np.where(length2 > 0, np.sum((c - heel) * along, axis=1) / length2, 0.0), 0.0, 1.0)
    return np.linalg.norm(c - heel - w[:, None] * along, axis=1)


def load_stays_under(scene: ContactScene, k: int, own: str, other: str, t0: float, t1: float) -> float | None:
    """Whether plate ``k`` carries only the foot ``own`` while the heel of ``other`` stands on it, from ``t0`` to
    ``t1`` (s): its centre of pressure, at every sample at or above the on-threshold, nearer ``own``'s foot
    (heel-toe segment, :func:`_foot_distance`) than ``other``'s. Both feet on one plate put it between them,
    under the one that carries more: nearer ``other`` once that foot takes half the load or more.

    Returns
    -------
    float or None
        NaN when the load stays under ``own`` throughout; else the first time (s) it is not nearer ``own``
        (a missing marker counts as not nearer); None without a centre of pressure or loaded samples.
    """
    loads = _loaded_cop(scene, k, t0, t1)
    if loads is None or not loads[0].size:
        return None
    t, cop, _ = loads
    flat = _plane(scene, k)
    nearer = _foot_distance(scene, flat, own, t, cop) < _foot_distance(scene, flat, other, t, cop)
    return np.nan if nearer.all() else float(t[np.argmin(nearer)])


class Verdict(NamedTuple):
    """A contact's foot (``""`` if unknown or ambiguous), flag (:data:`loper_analysis.constants.CONTACT_FLAGS`),
    reason in words (``""`` for ``ok``) and the heels on its plate (at the start probe or dwelling)."""

    side: str
    flag: str
    reason: str
    present: frozenset


def _off_edge_heels(scene: ContactScene, k: int, heels: Mapping[str, dict]) -> dict[str, float]:
    """The low heels (side: m outside the outline at the start probe) within reach of plate ``k`` that stand on
    no other plate (``heels``: :func:`heel_offsets`)."""
    window, on_all = heels["window"], heels["on_all"]
    return {
        s: window[s][0][0]
        for s in SIDES
        if window[s][0][0] <= scene.reach_m
        and window[s][1][0] <= scene.max_height_m
        and not np.delete(on_all[s], k).any()
    }


def _off_plate(side: str, near: Mapping[str, float], probe: float, landing: dict | None) -> str:
    """The reason of an ``off_plate`` contact: the heel's distance off the edge and, with a centre of pressure,
    where the plate took its first load (:func:`heel_landing`)."""
    said = f"heel off the plate's edge: the {side} heel {near[side] * 1000:.0f} mm off it at {probe:.3f} s"
    if landing is not None:
        said += (
            f", and the plate's first load (its centre of pressure at {landing['from_s']:.3f}-"
            f"{landing['to_s']:.3f} s) {landing['heel_m'] * 1000:.0f} mm from the {side} heel marker, nearest the "
            f"{landing['nearest']} marker ({landing['toe_m'] * 1000:.0f} mm from the {side} toe)"
        )
    return said + "; the foot loaded the plate without its heel, so the loading is not a heel strike"


def _two_feet(at_start, dwells, stays, side: str, shared: Mapping, probe: float) -> str:
    """The reason of a ``two_feet`` contact: both heels on the plate at the start probe (s), or the stay (s) of
    the heel that dwells and, with a centre of pressure, when the load came nearer that foot (``shared``)."""
    if len(at_start) == 2:
        return f"two feet on one plate: both heels on it at {probe:.3f} s"
    s = next(iter(dwells))
    said = (
        f"two feet on one plate: the {s} heel stands on it from {stays[s][0]:.3f} to {stays[s][1]:.3f} s "
        f"while the {side} foot is on it"
    )
    if shared.get(s) is not None:
        said += f"; the plate's centre of pressure nearer the {s} foot than the {side} foot at {shared[s]:.3f} s"
    return said


def contact_verdict(
    c,
    k: int,
    times: np.ndarray,
    need: float,
    heels: Mapping[str, dict],
    belt_side: str | None,
    scene: ContactScene,
) -> Verdict:
    """The verdict on contact ``c`` (a row of :func:`loper_analysis.gait.plate_contacts.plate_contacts`) of plate ``k``.

    ``times`` (s): the window's probes and frames; ``need`` (s): the unbroken time on the plate that makes a
    heel dwell; ``heels``: :func:`heel_offsets`; ``belt_side``: the side ``plate_sides`` gives the plate (None).
    A heel off the edge whose heel took the plate's first load (:func:`heel_landing`) is the contact's foot;
    another heel standing on the plate is no second foot while the plate's load stays under the contact's foot
    (:func:`load_stays_under`).
    """
    window, start_on, missing = heels["window"], heels["start_on"], heels["missing"]
    probe, height = times[0], scene.max_height_m
    at_start = [s for s in SIDES if start_on[s]]
    side = at_start[0] if len(at_start) == 1 else ""
    near, landing = {} if at_start else _off_edge_heels(scene, k, heels), None
    if near:
        landing = heel_landing(scene, k, c.start_s, min(near, key=near.get))
        if landing is not None and landing["on"]:
            side = min(near, key=near.get)  # its heel took the first load: it landed on the plate
    others = [s for s in SIDES if s != side]
    # another heel stands on this plate: on it, not inside another plate's outline
    stays = {
        s: _standing_run(times, on_plate(scene, *window[s]) & ~heels["elsewhere"][s], window[s][1], height)
        for s in others
    }
    dwells = {s for s in others if stays[s][1] - stays[s][0] >= need}
    shared = {s: load_stays_under(scene, k, side, s, *stays[s]) if side else None for s in dwells}
    dwells -= {s for s, t in shared.items() if t is not None and np.isnan(t)}  # the load stays under one foot
    undecided = [
        s
        for s in others
        if s not in dwells
        and missing[s].any()
        and _longest_run_s(times, on_plate(scene, *window[s]) | missing[s]) >= need
    ]
    present = frozenset(at_start) | dwells | ({side} if side else set())
    if c.incomplete:
        when = "the start" if c.start_sample == 0 else "the end"
        return Verdict(side, "incomplete", f"the plate is loaded at {when} of the recording", present)
    gone = [s for s in SIDES if missing[s][0]]
    if gone or undecided:
        said = (
            f"the {' and '.join(gone)} heel marker missing at {probe:.3f} s, where the foot is decided"
            if gone
            else f"the {undecided[0]} heel marker missing while it may stand on the plate"
        )
        return Verdict(side, "heel_missing", said, present)
    if len(present) == 2:
        return Verdict(side, "two_feet", _two_feet(at_start, dwells, stays, side, shared, probe), present)
    if not side and not at_start:
        if not near:
            elsewhere = [
                f"the {s} heel on plate {scene.numbers[j]}"
                for s in SIDES
                for j in np.flatnonzero(heels["on_all"][s])
                if j != k
            ]
            said = (
                f"no foot found: no heel on the plate at {probe:.3f} s, and none low within "
                f"{scene.reach_m * 1000:.0f} mm of it that stands on no other plate"
                + (f" ({', '.join(elsewhere)})" if elsewhere else "")
            )
            return Verdict("", "no_foot", said, present)
        side = min(near, key=near.get)
        if present - {side}:
            s = next(iter(present - {side}))
            said = (
                f"two feet on one plate: the {s} heel stands on it from {stays[s][0]:.3f} to {stays[s][1]:.3f} s, "
                f"the {side} heel {near[side] * 1000:.0f} mm off its edge at {probe:.3f} s"
            )
            return Verdict("", "two_feet", said, present)
        return Verdict(side, "off_plate", _off_plate(side, near, probe, landing), present)
    if (side if belt_side is None else belt_side) != side:
        said = f"the {side} foot on the {belt_side} foot's plate (events.plate_sides)"
        return Verdict(side, "wrong_belt", said, present)
    return Verdict(side, "ok", "", present)
