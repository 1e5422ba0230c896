"""Foot contacts on force plates: contacts per plate, the foot on each, flags and the gait events.

* :func:`plate_contacts` - loaded periods of one plate from its vertical force
  above the resting level (the hysteresis of :func:`loper_analysis.gait.events.load_transitions`);
* :func:`foot_contacts` - the contacts of every plate, each given a foot from
  the heel markers shortly after the contact starts, a flag
  (:data:`loper_analysis.constants.CONTACT_FLAGS`) and, when flagged, the
  reason in words; the contacts one foot makes on several plates at once
  joined into one foot contact (the foot told by its heel and toe markers);
* :func:`contact_events` - the event table of the clean foot contacts, with
  the spans of the flagged ones that strides must not cross.

Time in s, force in N, positions in m (markers and plate corners in one
frame). ``docs/events.md`` explains the rules.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pandas as pd

from loper_analysis.checks import integer, number, time_vector, where
from loper_analysis.checks import side as check_side
from loper_analysis.constants import CONTACT_FLAGS, FLAGGED_EVENTS, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.events import (
    EVENT_COLUMNS,
    MIN_STANCE_S,
    MIN_SWING_S,
    THRESHOLD_OFF_N,
    THRESHOLD_ON_N,
    load_transitions,
)
from loper_analysis.gait.plate_geometry import plate_axes, plate_offsets

__all__ = [
    "PLATE_CONTACT_COLUMNS",
    "CONTACT_COLUMNS",
    "PlateForce",
    "plate_contacts",
    "foot_contacts",
    "contact_events",
    "count_flagged",
]

logger = logging.getLogger(__name__)

#: Columns of :func:`plate_contacts`.
PLATE_CONTACT_COLUMNS: tuple[str, ...] = ("contact", "start_sample", "end_sample", "start_s", "end_s", "incomplete")
#: Columns of :func:`foot_contacts` (the heel columns are measured at the start probe).
CONTACT_COLUMNS: tuple[str, ...] = (
    "plate",
    "contact",
    "side",
    "flag",
    "start_sample",
    "end_sample",
    "start_s",
    "end_s",
    "belt_side",
    *(f"{s}_heel_{q}_m" for s in SIDES for q in ("outside", "height")),
    "foot_contact",
    "reason",
)
#: Flags of a contact no heel explains by standing on its plate: another plate's contact of the same foot may.
_JOINABLE = {"no_foot", "off_plate"}
#: Flags whose contact may hide either foot: they block the strides of both sides.
_BOTH_SIDES = {"heel_missing", "two_feet", "no_foot"}


@dataclass(frozen=True)
class PlateForce:
    """One force plate: its vertical force above the resting level and its corners.

    Attributes
    ----------
    plate : int
        Plate number as in the recording (1, 2, ...).
    time_s : numpy.ndarray, shape (n_samples,)
        Sample times in s on the marker clock.
    vertical_force_n : numpy.ndarray, shape (n_samples,)
        Vertical force in N minus the plate's resting (unloaded) level,
        positive when loaded.
    corners_m : numpy.ndarray, shape (4, 3)
        The plate's corners in m, in order around the plate, in the frame of the markers.
    """

    plate: int
    time_s: np.ndarray
    vertical_force_n: np.ndarray
    corners_m: np.ndarray


def plate_contacts(
    time_s,
    vertical_force_n,
    threshold_on_n: float = THRESHOLD_ON_N,
    threshold_off_n: float = THRESHOLD_OFF_N,
    min_stance_s: float = MIN_STANCE_S,
    min_swing_s: float = MIN_SWING_S,
    source: str = "",
) -> pd.DataFrame:
    """Loaded periods (contacts) of one plate from its vertical force above the resting level.

    A contact starts at the first sample with force ``>= threshold_on_n``
    (the heel strike of :func:`loper_analysis.gait.events.gait_events`) and ends at
    the first later sample with force ``<= threshold_off_n`` (the toe-off),
    with the same hysteresis and minimum durations. A plate loaded when the
    trial starts (or reaching the loaded state from the dead band first) gives
    a contact from sample 0, one still loaded at the end a contact to the last
    sample; both are ``incomplete``. A plate never loaded gives no row.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    vertical_force_n : array_like, shape (n_samples,)
        Vertical force in N above the plate's resting level; finite.
    threshold_on_n, threshold_off_n : float
        Loading and unloading thresholds in N above the resting level; on > off.
    min_stance_s, min_swing_s : float
        Shortest accepted loaded and unloaded period in s.
    source : str
        Name of the trial and plate, quoted in messages.

    Returns
    -------
    pandas.DataFrame
        One row per contact in time order (:data:`PLATE_CONTACT_COLUMNS`):
        ``contact`` (0, 1, ...), ``start_sample``, ``end_sample`` (int,
        indices into ``time_s``), ``start_s``, ``end_s`` (s), ``incomplete``
        (bool). ``attrs["dropped"]``: the periods removed as too short.

    Raises
    ------
    LoperInputError
        As :func:`loper_analysis.gait.events.load_transitions`.
    """
    t = time_vector(time_s, source)
    samples, loading, dropped = load_transitions(
        t, vertical_force_n, threshold_on_n, threshold_off_n, min_stance_s, min_swing_s, source
    )
    starts, ends = list(samples[loading]), list(samples[~loading])
    open_start = bool(samples.size) and not loading[0]
    if not samples.size:  # no transition left: loaded throughout or never loaded
        open_start = _loaded_at_end(
            np.asarray(vertical_force_n, dtype=float), float(threshold_on_n), float(threshold_off_n)
        )
    if open_start:
        starts.insert(0, 0)
    open_end = len(starts) > len(ends)
    if open_end:
        ends.append(t.size - 1)
    start = np.asarray(starts, dtype=np.int64)
    end = np.asarray(ends, dtype=np.int64)
    incomplete = np.zeros(start.size, dtype=bool)
    if start.size:
        incomplete[0] |= open_start
        incomplete[-1] |= open_end
    table = pd.DataFrame(
        {
            "contact": np.arange(start.size, dtype=np.int64),
            "start_sample": start,
            "end_sample": end,
            "start_s": t[start],
            "end_s": t[end],
            "incomplete": incomplete,
        },
        columns=list(PLATE_CONTACT_COLUMNS),
    )
    table.attrs["dropped"] = dropped
    return table


def _loaded_at_end(f: np.ndarray, on: float, off: float) -> bool:
    """Whether the hysteresis ends loaded: the force last reached ``on`` after it last fell to ``off``."""
    high, low = np.flatnonzero(f >= on), np.flatnonzero(f <= off)
    return bool(high.size) and (not low.size or high[-1] > low[-1])


def _at(time_s: np.ndarray, xyz: np.ndarray, when: np.ndarray) -> np.ndarray:
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


def foot_contacts(
    plates: Sequence[PlateForce],
    marker_time_s,
    heels_m: Mapping[str, np.ndarray],
    *,
    toes_m: Mapping[str, np.ndarray] | None = None,
    plate_sides: Mapping[str, int] | None = None,
    threshold_on_n: float = THRESHOLD_ON_N,
    threshold_off_n: float = THRESHOLD_OFF_N,
    min_stance_s: float = MIN_STANCE_S,
    min_swing_s: float = MIN_SWING_S,
    delay_s: float = 0.05,
    dwell_s: float = 0.15,
    margin_m: float = 0.03,
    reach_m: float = 0.25,
    max_height_m: float = 0.12,
    vertical_axis: int | None = None,
    source: str = "",
    up: Sequence[float] | None = None,
) -> pd.DataFrame:
    """The contacts of every plate, each with the foot on it (from the heel markers), a flag and its reason.

    A heel is **on** a plate at an instant when it lies over the plate's
    outline (at most ``margin_m`` outside) and at most ``max_height_m`` above
    its surface. Each contact is judged in its **window**, from the start
    probe ``start + delay_s`` (the foot that loaded the plate has landed) to
    the end probe ``end - delay_s`` (both at the contact's middle if it is
    shorter than ``2 * delay_s``), at the probes and every marker frame
    between them. The contact's foot is the heel on the plate at the start
    probe. Another heel **dwells** on the plate when it is on it without a
    break for ``dwell_s`` (or the whole window, if shorter) and that stay
    does not end with the heel still low but off the plate: a swing foot
    passing low over a plate, or coming down just beside its edge, does not
    dwell; a foot standing on it does. Flags, the first that applies:

    * ``incomplete`` - the contact touches the start or end of the recording;
    * ``heel_missing`` - a heel is missing (NaN, or outside the marker time)
      at the start probe, or another heel is missing in the window where
      the gap decides whether it dwells;
    * ``two_feet`` - both heels on the plate at the start probe, or the
      other heel dwells on it during the window (it arrived before the first
      foot left);
    * ``no_foot`` - no heel on the plate at the start probe and no low heel
      (at most ``max_height_m`` above it) within ``reach_m`` that is not on
      another plate: a load no foot explains;
    * ``off_plate`` - no heel on the plate at the start probe, but the
      nearest low heel within ``reach_m`` (not on another plate) explains it:
      that foot (``side``) loaded the plate with its heel off it, so the
      loading is not its heel strike;
    * ``wrong_belt`` - ``plate_sides`` gives the plate to the other side;
    * ``ok`` - one heel on the plate, alone, as configured.

    **A foot across plates.** A ``no_foot`` or ``off_plate`` contact that
    overlaps in time an ``ok`` contact of one foot on another plate, with that
    foot's toe (or heel) on this plate at its start probe and the other foot
    neither dwelling on it nor with its toe on it then, is that foot's too:
    its heel stands on the other plate (``ok``, that side). The ``ok``
    contacts of one foot that overlap in time form one **foot contact**
    (``foot_contact``): its heel strike is the first plate's loading, its
    toe-off the last plate's unloading (:func:`contact_events`). Without
    ``toes_m`` only the heels tell.

    Every flagged contact is logged with its reason: a WARNING for those left
    out of the events (every flag but ``ok`` and ``incomplete``), INFO for
    ``incomplete``.

    Parameters
    ----------
    plates : sequence of PlateForce
        The plates, with distinct numbers; force above the resting level.
    marker_time_s : array_like, shape (n_frames,)
        Times of the marker frames in s, on the plates' clock.
    heels_m : mapping
        ``{"left": (n_frames, 3), "right": (n_frames, 3)}`` heel marker
        positions in m (NaN where missing), in the frame of the corners.
    toes_m : mapping, optional
        Toe marker positions of both feet in m, like ``heels_m``; they only
        join a foot's contacts on several plates.
    plate_sides : mapping, optional
        ``{"left": plate, "right": plate}``: the plate (belt) each foot should
        use. Only a check (``wrong_belt``); the foot always comes from the markers.
    threshold_on_n, threshold_off_n, min_stance_s, min_swing_s : float
        Contact detection (:func:`plate_contacts`), N above the resting level and s.
    delay_s : float
        Time after the contact's start (before its end) at which the window opens (closes), s.
    dwell_s : float
        Shortest unbroken time on the plate that makes a second foot, s.
    margin_m : float
        How far outside the outline a heel still counts as over the plate, m.
    reach_m : float
        How far outside a low heel may be and still explain a contact (``off_plate``), m.
    max_height_m : float
        Highest heel above the plate's surface that counts as on it, m.
    vertical_axis : {0, 1, 2} or None
        The vertical coordinate axis; None: each plate's normal (from its
        corners, which may run either way round the plate).
    source : str
        Name of the trial, quoted in messages.
    up : array_like, shape (3,), optional
        The up direction in the frame of the corners and heels (the model's
        +Y, :data:`loper_analysis.motion.markers.MODEL_UP`, for corners rotated like
        the markers). With ``vertical_axis`` None each plate's normal is turned
        along it and a plate more than 45 deg from level is refused, naming it.

    Returns
    -------
    pandas.DataFrame
        One row per contact (:data:`CONTACT_COLUMNS`), ordered by start time
        then plate: ``plate``, ``contact`` (per plate), ``side`` (the foot;
        ``""`` if unknown or ambiguous), ``flag``, ``start_sample``,
        ``end_sample`` (indices into that plate's ``time_s``), ``start_s``,
        ``end_s`` (s), ``belt_side`` (the side ``plate_sides`` gives the plate,
        or ``""``), per side the heel's distance outside the plate and
        height above it at the start probe (m), ``foot_contact`` (0, 1, ...
        in time order; the contacts of one foot on several plates share it)
        and ``reason`` (why the contact gives no events, in words; ``""`` for
        ``ok``).

    Raises
    ------
    LoperInputError
        Bad plates, marker shapes, sides, settings or plate numbers in ``plate_sides``.
    """
    tm = time_vector(marker_time_s, source, name="marker_time_s", item="frame")
    heels = _checked_heels(heels_m, tm.size, source)
    toes = None if toes_m is None else _checked_heels(toes_m, tm.size, source, "toes_m")
    plates = list(plates)
    numbers = [integer("plate", p.plate, source, minimum=0) for p in plates]
    if len(set(numbers)) != len(numbers):
        raise LoperInputError(f"{where(source)}plate numbers must be distinct, got {numbers}")
    belt = _belt_sides(plate_sides, numbers, source)
    delay = number("delay_s", delay_s, source, minimum=0.0)
    dwell = number("dwell_s", dwell_s, source, minimum=0.0)
    margin = number("margin_m", margin_m, source, minimum=0.0)
    reach = number("reach_m", reach_m, source, minimum=0.0)
    height = number("max_height_m", max_height_m, source, minimum=0.0)
    names = [f"{where(source)}plate {n}" for n in numbers]
    corners = [np.asarray(p.corners_m, dtype=float) for p in plates]
    for name, c in zip(names, corners):
        plate_axes(c, vertical_axis, name, up)
    scene = _Scene(tm, heels, toes, corners, numbers, vertical_axis, up, delay, dwell, margin, reach, height)

    rows = []
    for k, (plate, name) in enumerate(zip(plates, names)):
        found = plate_contacts(
            plate.time_s,
            plate.vertical_force_n,
            threshold_on_n,
            threshold_off_n,
            min_stance_s,
            min_swing_s,
            source=name,
        )
        for c in found.itertuples():
            rows.append(_contact_row(c, k, numbers[k], belt, scene))
    return _contact_table(_join_feet(rows, scene), source)


class _Scene(NamedTuple):
    """What the contacts of a trial are judged against (:func:`foot_contacts`).

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


def _on(scene: _Scene, outside: np.ndarray, above: np.ndarray) -> np.ndarray:
    """Whether heels at ``outside`` (m outside the outline) and ``above`` (m above the surface) are on the plate."""
    return (outside <= scene.margin_m) & (above <= scene.max_height_m)  # NaN: False


def _heel_offsets(scene: _Scene, k: int, times: np.ndarray) -> dict[str, dict]:
    """Per side the heel over plate ``k`` at the window's ``times`` (s).

    ``window``: ``(outside, above)`` (m, each (n_times,)); ``start_on``: on the plate at the start probe;
    ``missing`` (n_times,): NaN heel; ``on_all`` (n_plates,): on each plate at the start probe; ``elsewhere``
    (n_times,): inside another plate's outline, outside this one's (it stands on that plate).
    """
    start_on, on_all, missing, window, elsewhere = {}, {}, {}, {}, {}
    for s in SIDES:
        xyz = _at(scene.marker_time_s, scene.heels_m[s], times)
        out, above = plate_offsets(xyz, scene.corners_m[k], scene.vertical_axis, up=scene.up)
        window[s] = (out, above)
        start_on[s] = _on(scene, out[:1], above[:1])[0]
        missing[s] = np.isnan(out)
        # on every plate at the start probe: (n_plates,) outside, height
        on_all[s] = np.array(
            [_on(scene, *plate_offsets(xyz[:1], cc, scene.vertical_axis, up=scene.up))[0] for cc in scene.corners_m]
        )
        inside = np.zeros(out.shape, dtype=bool)
        for j, cc in enumerate(scene.corners_m):
            if j != k:
                inside |= plate_offsets(xyz, cc, scene.vertical_axis, up=scene.up)[0] == 0
        elsewhere[s] = inside & (out > 0)
    return {"window": window, "start_on": start_on, "missing": missing, "on_all": on_all, "elsewhere": elsewhere}


class _Verdict(NamedTuple):
    """A contact's foot (``""`` if unknown or ambiguous), flag (:data:`CONTACT_FLAGS`), reason in words (``""``
    for ``ok``) and the heels on its plate (at the start probe or dwelling)."""

    side: str
    flag: str
    reason: str
    present: frozenset


def _side_and_flag(
    c,
    k: int,
    times: np.ndarray,
    need: float,
    heels: Mapping[str, dict],
    belt_side: str | None,
    scene: _Scene,
) -> _Verdict:
    """The verdict on contact ``c`` (a row of :func:`plate_contacts`) of plate ``k``.

    ``times`` (s): the window's probes and frames; ``need`` (s): the unbroken time on the plate that makes a
    heel dwell; ``heels``: :func:`_heel_offsets`; ``belt_side``: the side ``plate_sides`` gives the plate (None).
    """
    window, start_on, missing, on_all = heels["window"], heels["start_on"], heels["missing"], heels["on_all"]
    elsewhere = heels["elsewhere"]
    probe, height = times[0], scene.max_height_m
    at_start = [s for s in SIDES if start_on[s]]
    side = at_start[0] if len(at_start) == 1 else ""
    others = [s for s in SIDES if s != side]
    # another heel stands on this plate: on it, not inside another plate's outline
    stays = {s: _standing_run(times, _on(scene, *window[s]) & ~elsewhere[s], window[s][1], height) for s in others}
    dwells = {s for s in others if stays[s][1] - stays[s][0] >= need}
    undecided = [
        s
        for s in others
        if s not in dwells and missing[s].any() and _longest_run_s(times, _on(scene, *window[s]) | missing[s]) >= need
    ]
    present = frozenset(at_start) | dwells
    if c.incomplete:
        when = "the start" if c.start_sample == 0 else "the end"
        return _Verdict(side, "incomplete", f"the plate is loaded at {when} of the recording", present)
    gone = [s for s in SIDES if missing[s][0]]
    if gone or undecided:
        said = (
            f"the {' and '.join(gone)} heel marker missing at {probe:.3f} s, where the foot is decided"
            if gone
            else f"the {undecided[0]} heel marker missing while it may stand on the plate"
        )
        return _Verdict(side, "heel_missing", said, present)
    if len(present) == 2:
        if len(at_start) == 2:
            said = f"two feet on one plate: both heels on it at {probe:.3f} s"
        else:
            s = next(iter(dwells))
            said = (
                f"two feet on one plate: the {s} heel stands on it from {stays[s][0]:.3f} to {stays[s][1]:.3f} s "
                f"while the {side} foot is on it"
            )
        return _Verdict(side, "two_feet", said, present)
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
            return _Verdict("", "no_foot", said, present)
        side = min(near, key=near.get)
        if present - {side}:
            s = next(iter(present - {side}))
            said = (
                f"two feet on one plate: the {s} heel stands on it from {stays[s][0]:.3f} to {stays[s][1]:.3f} s, "
                f"the {side} heel {near[side] * 1000:.0f} mm off its edge at {probe:.3f} s"
            )
            return _Verdict("", "two_feet", said, present)
        said = (
            f"heel off the plate's edge: the {side} heel {near[side] * 1000:.0f} mm off it at {probe:.3f} s; the "
            "foot loaded the plate without its heel, so the loading is not a heel strike"
        )
        return _Verdict(side, "off_plate", said, present)
    if (side if belt_side is None else belt_side) != side:
        said = f"the {side} foot on the {belt_side} foot's plate (events.plate_sides)"
        return _Verdict(side, "wrong_belt", said, present)
    return _Verdict(side, "ok", "", present)


def _contact_row(c, k: int, number: int, belt: Mapping[int, str], scene: _Scene) -> dict:
    """The row (:data:`CONTACT_COLUMNS`) of contact ``c`` (a row of :func:`plate_contacts`) of plate ``k``,
    numbered ``number``; ``belt``: ``{plate number: side}``. The keys ``_k``, ``_probe`` (s) and ``_present``
    (the heels on the plate) serve :func:`_join_feet`."""
    mid = 0.5 * (c.start_s + c.end_s)
    ps, pe = min(c.start_s + scene.delay_s, mid), max(c.end_s - scene.delay_s, mid)
    tm = scene.marker_time_s
    times = np.concatenate([[ps], tm[(tm > ps) & (tm < pe)], [pe] if pe > ps else []])
    need = min(scene.dwell_s, pe - ps)
    heels = _heel_offsets(scene, k, times)
    verdict = _side_and_flag(c, k, times, need, heels, belt.get(number), scene)
    window = heels["window"]
    return {
        "plate": number,
        "contact": c.contact,
        "side": verdict.side,
        "flag": verdict.flag,
        "start_sample": c.start_sample,
        "end_sample": c.end_sample,
        "start_s": c.start_s,
        "end_s": c.end_s,
        "belt_side": belt.get(number, ""),
        **{f"{s}_heel_{q}_m": float(window[s][i][0]) for s in SIDES for i, q in enumerate(("outside", "height"))},
        "foot_contact": -1,
        "reason": verdict.reason,
        "_k": k,
        "_probe": ps,
        "_present": verdict.present,
    }


def _foot_on(scene: _Scene, side: str, k: int, when: float) -> bool:
    """Whether the toe or the heel of ``side`` is on plate ``k`` at ``when`` (s); False without toe markers."""
    if scene.toes_m is None:
        return False
    xyz = np.vstack([_at(scene.marker_time_s, m[side], np.array([when])) for m in (scene.toes_m, scene.heels_m)])
    return bool(_on(scene, *plate_offsets(xyz, scene.corners_m[k], scene.vertical_axis, up=scene.up)).any())


def _overlap(a: dict, b: dict) -> bool:
    """Whether contacts ``a`` and ``b`` (rows) are loaded at once, on different plates."""
    return a["plate"] != b["plate"] and a["start_s"] < b["end_s"] and b["start_s"] < a["end_s"]


def _join_feet(rows: list[dict], scene: _Scene) -> list[dict]:
    """The rows with the contacts of one foot on several plates joined (:func:`foot_contacts`): a ``no_foot`` or
    ``off_plate`` contact made ``ok`` for the foot whose heel stands on an overlapping ``ok`` contact's plate and
    whose toe (or heel) is on this plate at its start probe, the other foot not on it; ``foot_contact`` set."""
    for b in rows:
        if b["flag"] not in _JOINABLE:
            continue
        feet = [
            s
            for s in SIDES
            if any(a["flag"] == "ok" and a["side"] == s and _overlap(a, b) for a in rows)
            and _foot_on(scene, s, b["_k"], b["_probe"])
        ]
        if len(feet) != 1:
            continue
        other = next(s for s in SIDES if s != feet[0])
        if other in b["_present"] or _foot_on(scene, other, b["_k"], b["_probe"]):
            continue
        b.update(side=feet[0], flag="ok", reason="")
    # one foot contact: the ok contacts of one foot loaded at once (union-find over the rows)
    root = list(range(len(rows)))

    def find(i: int) -> int:
        while root[i] != i:
            i = root[i]
        return i

    for i, a in enumerate(rows):
        for j, b in enumerate(rows[:i]):
            if a["flag"] == b["flag"] == "ok" and a["side"] == b["side"] and _overlap(a, b):
                root[find(i)] = find(j)
    for i, r in enumerate(rows):
        r["_group"] = find(i)
    return rows


def _contact_table(rows: Sequence[dict], source: str) -> pd.DataFrame:
    """The contact table of :func:`foot_contacts` from its rows, ordered by start time then plate, foot contacts
    numbered in time order; every flagged contact logged with its reason (a warning when it is left out)."""
    groups = [r["_group"] for r in rows]
    table = pd.DataFrame(rows, columns=list(CONTACT_COLUMNS))
    table = table.astype(
        {
            "plate": np.int64,
            "contact": np.int64,
            "start_sample": np.int64,
            "end_sample": np.int64,
            "start_s": float,
            "end_s": float,
            "foot_contact": np.int64,
            "reason": object,
        }
    )
    table["_group"] = pd.Series(groups, dtype=np.int64)
    table = table.sort_values(["start_s", "plate"], kind="stable", ignore_index=True)
    order = {g: n for n, g in enumerate(dict.fromkeys(table["_group"]))}
    table["foot_contact"] = table["_group"].map(order).astype(np.int64)
    table = table.drop(columns="_group")
    for r in table[table["flag"] != "ok"].itertuples():
        logger.log(
            logging.INFO if r.flag == "incomplete" else logging.WARNING,
            "%splate %d contact %.3f-%.3f s (%s foot) left out of the events, %s: %s",
            where(source),
            r.plate,
            r.start_s,
            r.end_s,
            r.side or "unknown",
            r.flag,
            r.reason,
        )
    for _, joined in table[table["flag"] == "ok"].groupby("foot_contact"):
        if len(joined) > 1:
            logger.info(
                "%sthe %s foot across plates %s: one contact %.3f-%.3f s",
                where(source),
                joined["side"].iloc[0],
                " and ".join(str(p) for p in joined["plate"]),
                joined["start_s"].min(),
                joined["end_s"].max(),
            )
    table.attrs["source"] = source
    return table


def _checked_heels(
    heels_m: Mapping[str, np.ndarray], n_frames: int, source: str, name: str = "heels_m"
) -> dict[str, np.ndarray]:
    """``{side: (n_frames, 3) float array}`` for both sides (``name``: the argument, in messages)."""
    what = "heel" if name == "heels_m" else "toe"
    if not isinstance(heels_m, Mapping) or set(heels_m) != set(SIDES):
        keys = sorted(heels_m) if isinstance(heels_m, Mapping) else type(heels_m).__name__
        raise LoperInputError(f"{where(source)}{name} must map each of {SIDES} to a {what} trajectory, got {keys}")
    out = {}
    for s in SIDES:
        a = np.asarray(heels_m[s], dtype=float)
        if a.shape != (n_frames, 3):
            raise LoperInputError(
                f"{where(source)}{name}[{s!r}] must have shape ({n_frames}, 3) like marker_time_s, got {a.shape}"
            )
        out[s] = a
    return out


def _belt_sides(plate_sides: Mapping[str, int] | None, numbers: list[int], source: str) -> dict[int, str]:
    """``{plate number: side}`` from ``{side: plate number}``."""
    if plate_sides is None:
        return {}
    belt = {}
    for s, n in plate_sides.items():
        check_side(s, source)
        n = integer(f"plate_sides[{s!r}]", n, source)
        if n not in numbers:
            raise LoperInputError(f"{where(source)}plate_sides[{s!r}] is plate {n}; the plates are {numbers}")
        if n in belt:
            raise LoperInputError(f"{where(source)}plate_sides gives plate {n} to both sides")
        belt[n] = s
    return belt


def count_flagged(flags) -> int:
    """Number of contacts left out for a reason: flags other than ``ok`` and ``incomplete``.

    ``flags`` is the ``flag`` column of a contact table (:data:`CONTACT_COLUMNS`);
    contacts cut by the start or end of the recording are not counted (a
    trial's first and last periods never give events).
    """
    flags = pd.Series(flags, dtype=object)
    return int((~flags.isin(["ok", "incomplete"])).sum())


def contact_events(contacts: pd.DataFrame) -> pd.DataFrame:
    """Event table of a contact table: heel strike and toe-off of each clean foot contact, spans of the flagged ones.

    The ``ok`` contacts of one foot contact (column ``foot_contact``, when
    present: a foot across several plates) give one ``heel_strike`` at the
    earliest start (first sample at or above the on-threshold of the first
    plate loaded) and one ``toe_off`` at the latest end (first sample at or
    below the off-threshold of the last plate unloaded), of their side;
    without the column each ``ok`` contact is a foot contact of its own. Any
    other flag gives no gait event but a ``flagged_start`` / ``flagged_end``
    pair at the contact's start and end, for its side - for both sides when
    the foot is unknown or the flag is ``heel_missing``, ``two_feet`` or
    ``no_foot`` - so that :func:`loper_analysis.gait.strides.strides_from_events`
    leaves out strides that span it.

    Parameters
    ----------
    contacts : pandas.DataFrame
        Columns ``side``, ``flag``, ``start_s``, ``end_s``, ``start_sample``,
        ``end_sample``, optionally ``foot_contact`` (:func:`foot_contacts`).

    Returns
    -------
    pandas.DataFrame
        :data:`loper_analysis.gait.events.EVENT_COLUMNS` (``side``, ``event``,
        ``time_s``, ``sample``), sorted by time then side.
    """
    source = str(contacts.attrs.get("source", "")) if isinstance(contacts, pd.DataFrame) else ""
    needed = ["side", "flag", "start_s", "end_s", "start_sample", "end_sample"]
    if not isinstance(contacts, pd.DataFrame) or not set(needed) <= set(contacts.columns):
        raise LoperInputError(f"{where(source)}contacts must be a table with columns {needed}")
    unknown = sorted(set(contacts["flag"]) - set(CONTACT_FLAGS))
    if unknown:
        raise LoperInputError(f"{where(source)}contacts: unknown flag(s) {unknown}; known: {list(CONTACT_FLAGS)}")
    rows = []
    ok = contacts[contacts["flag"] == "ok"]
    groups = ok["foot_contact"] if "foot_contact" in ok.columns else pd.Series(range(len(ok)), index=ok.index)
    for _, foot in ok.groupby(groups.to_numpy(), sort=False):
        sides = set(foot["side"])
        if len(sides) != 1:
            raise LoperInputError(f"{where(source)}contacts: one foot contact with the sides {sorted(sides)}")
        side = check_side(sides.pop(), source)
        first, last = foot.loc[foot["start_s"].idxmin()], foot.loc[foot["end_s"].idxmax()]
        rows += [
            (side, "heel_strike", first["start_s"], first["start_sample"]),
            (side, "toe_off", last["end_s"], last["end_sample"]),
        ]
    for c in contacts[contacts["flag"] != "ok"].itertuples():
        sides = SIDES if (c.flag in _BOTH_SIDES or c.side not in SIDES) else (c.side,)
        for s in sides:
            rows += [(s, FLAGGED_EVENTS[0], c.start_s, c.start_sample), (s, FLAGGED_EVENTS[1], c.end_s, c.end_sample)]
    table = pd.DataFrame(rows, columns=list(EVENT_COLUMNS))
    table = table.astype({"time_s": float, "sample": np.int64})
    table = table.sort_values(["time_s", "side"], kind="stable", ignore_index=True)
    table.attrs["source"] = source
    return table
