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
from loper_analysis.gait.plate_geometry import plate_offsets

__all__ = ["ContactScene", "Verdict", "contact_verdict", "heel_offsets", "on_plate", "positions_at"]


class ContactScene(NamedTuple):
    """What the contacts of a trial are judged against (:func:`loper_analysis.gait.contacts.foot_contacts`).

    ``marker_time_s`` (n_frames,) in s; ``heels_m``, ``toes_m`` (or None): ``{side: (n_frames, 3)}`` in m;
    ``corners_m``: per plate its corners (4, 3) in m, ``numbers`` its number; ``vertical_axis`` and ``up``: the
    vertical; the checked probe delay and dwell time (s), margin, reach and highest heel (m).
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


class Verdict(NamedTuple):
    """A contact's foot (``""`` if unknown or ambiguous), flag (:data:`loper_analysis.constants.CONTACT_FLAGS`),
    reason in words (``""`` for ``ok``) and the heels on its plate (at the start probe or dwelling)."""

    side: str
    flag: str
    reason: str
    present: frozenset


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
    """
    window, start_on, missing, on_all = heels["window"], heels["start_on"], heels["missing"], heels["on_all"]
    elsewhere = heels["elsewhere"]
    probe, height = times[0], scene.max_height_m
    at_start = [s for s in SIDES if start_on[s]]
    side = at_start[0] if len(at_start) == 1 else ""
    others = [s for s in SIDES if s != side]
    # another heel stands on this plate: on it, not inside another plate's outline
    stays = {s: _standing_run(times, on_plate(scene, *window[s]) & ~elsewhere[s], window[s][1], height) for s in others}
    dwells = {s for s in others if stays[s][1] - stays[s][0] >= need}
    undecided = [
        s
        for s in others
        if s not in dwells
        and missing[s].any()
        and _longest_run_s(times, on_plate(scene, *window[s]) | missing[s]) >= need
    ]
    present = frozenset(at_start) | dwells
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
        if len(at_start) == 2:
            said = f"two feet on one plate: both heels on it at {probe:.3f} s"
        else:
            s = next(iter(dwells))
            said = (
                f"two feet on one plate: the {s} heel stands on it from {stays[s][0]:.3f} to {stays[s][1]:.3f} s "
                f"while the {side} foot is on it"
            )
        return Verdict(side, "two_feet", said, present)
    if not at_start:
        # low heels near this plate that stand on no other plate
        near = {
            s: window[s][0][0]
            for s in SIDES
            if window[s][0][0] <= scene.reach_m and window[s][1][0] <= height and not np.delete(on_all[s], k).any()
        }
        if not near:
            elsewhere = [
                f"the {s} heel on plate {scene.numbers[j]}" for s in SIDES for j in np.flatnonzero(on_all[s]) if j != k
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
        said = (
            f"heel off the plate's edge: the {side} heel {near[side] * 1000:.0f} mm off it at {probe:.3f} s; the "
            "foot loaded the plate without its heel, so the loading is not a heel strike"
        )
        return Verdict(side, "off_plate", said, present)
    if (side if belt_side is None else belt_side) != side:
        said = f"the {side} foot on the {belt_side} foot's plate (events.plate_sides)"
        return Verdict(side, "wrong_belt", said, present)
    return Verdict(side, "ok", "", present)
