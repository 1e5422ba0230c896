"""Foot contacts on force plates: the contact table of a trial, with the foot, flag and reason of each, and its
gait events.

* :func:`foot_contacts` - the contacts of every plate (:func:`loper_analysis.gait.plate_contacts.plate_contacts`), each
  given a foot from the heel markers shortly after the contact starts, a flag
  (:data:`loper_analysis.constants.CONTACT_FLAGS`) and, when flagged, the reason in words
  (:func:`loper_analysis.gait.contact_flags.contact_verdict`); the contacts one foot makes on several plates at once
  joined into one foot contact (:func:`loper_analysis.gait.foot_across_plates.join_feet`); every flagged contact logged
  with its reason;
* :func:`contact_events` - the event table of the clean foot contacts, with
  the spans of the flagged ones that strides must not cross;
* :func:`count_flagged` - the contacts left out for a reason.

Time in s, force in N, positions in m (markers and plate corners in one
frame). ``docs/events.md`` explains the rules.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from loper_analysis.checks import integer, number, time_vector, where
from loper_analysis.checks import side as check_side
from loper_analysis.constants import CONTACT_FLAGS, FLAGGED_EVENTS, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.contact_flags import ContactScene, contact_verdict, heel_offsets
from loper_analysis.gait.events import (
    EVENT_COLUMNS,
    MIN_STANCE_S,
    MIN_SWING_S,
    THRESHOLD_OFF_N,
    THRESHOLD_ON_N,
)
from loper_analysis.gait.foot_across_plates import join_feet
from loper_analysis.gait.plate_contacts import plate_contacts
from loper_analysis.gait.plate_geometry import plate_axes

__all__ = [
    "CONTACT_COLUMNS",
    "PlateForce",
    "foot_contacts",
    "contact_events",
    "count_flagged",
]

logger = logging.getLogger(__name__)

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
    cop_m : numpy.ndarray, shape (n_samples, 3), optional
        The plate's centre of pressure in m, in the frame of the markers (None: not known). Where the plate
        takes its first load and whether its load stays under one foot (:func:`foot_contacts`).
    """

    plate: int
    time_s: np.ndarray
    vertical_force_n: np.ndarray
    corners_m: np.ndarray
    cop_m: np.ndarray | None = None


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

    **The plate's force**, where a plate has its centre of pressure (``cop_m``): a low heel within ``reach_m``
    but past ``margin_m`` whose heel took the plate's first load (the nearest of the four foot markers to it,
    :func:`loper_analysis.gait.contact_flags.heel_landing`; toe markers needed) landed on the plate (not
    ``off_plate``); another heel dwelling on the plate is no second foot while the centre of pressure stays
    nearer the contact's foot than that one (:func:`loper_analysis.gait.contact_flags.load_stays_under`).

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
        Contact detection (:func:`loper_analysis.gait.plate_contacts.plate_contacts`), N above the resting level and s.
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
    scene = ContactScene(
        tm,
        heels,
        toes,
        corners,
        numbers,
        vertical_axis,
        up,
        delay,
        dwell,
        margin,
        reach,
        height,
        plates,
        threshold_on_n,
    )

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
    return _contact_table(join_feet(rows, scene), source)


def _contact_row(c, k: int, number: int, belt: Mapping[int, str], scene: ContactScene) -> dict:
    """The row (:data:`CONTACT_COLUMNS`) of contact ``c`` (a row of
    :func:`loper_analysis.gait.plate_contacts.plate_contacts`) of plate ``k``, numbered ``number``; ``belt``:
    ``{plate number: side}``. The keys ``_k``, ``_probe`` (s) and ``_present`` (the heels on the plate) serve
    :func:`loper_analysis.gait.foot_across_plates.join_feet`."""
    mid = 0.5 * (c.start_s + c.end_s)
    ps, pe = min(c.start_s + scene.delay_s, mid), max(c.end_s - scene.delay_s, mid)
    tm = scene.marker_time_s
    times = np.concatenate([[ps], tm[(tm > ps) & (tm < pe)], [pe] if pe > ps else []])
    need = min(scene.dwell_s, pe - ps)
    heels = heel_offsets(scene, k, times)
    verdict = contact_verdict(c, k, times, need, heels, belt.get(number), scene)
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
