"""A trial's gait events: heel strikes and toe-offs from the force platforms with the heel markers, or from one
vertical-force channel per belt whose feet the heel markers confirm (:func:`trial_events`); how, in
:class:`EventSettings`."""

from __future__ import annotations

import logging
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import ORDER
from loper_analysis.gait.events import MIN_STANCE_S, MIN_SWING_S, THRESHOLD_OFF_N, THRESHOLD_ON_N
from loper_analysis.gait.grf import MAX_RESTING_N, RESTING_BAND_N

__all__ = [
    "FOOT_MARKERS",
    "TOE_MARKERS",
    "GRF_CHANNELS",
    "MIN_JUDGED_STANCES",
    "SWAPPED_BELT_FRACTION",
    "EventSettings",
    "trial_events",
]

log = logging.getLogger(__name__)

#: Vertical-GRF analog channel of each belt in a file without force platforms (config ``events.grf_channels``).
GRF_CHANNELS: Mapping[str, str] = {"left": "Fz_left", "right": "Fz_right"}
#: Heel marker of each foot, model names (config ``events.foot_markers``).
FOOT_MARKERS: Mapping[str, str] = {"left": "LHEE", "right": "RHEE"}
#: Toe marker of each foot, model names: with the heels they tell the foot across two plates (used when present).
TOE_MARKERS: Mapping[str, str] = {"left": "LTOE", "right": "RTOE"}


@dataclass(frozen=True)
class EventSettings:
    """How heel strikes and toe-offs are found (config ``events.*``, ``grf.*``, ``markers.filter.order``).

    ``grf_channels``: {side: analog channel} of each belt (files without force platforms);
    ``threshold_on_n`` / ``threshold_off_n``: the vertical force (N) rises / falls through these at heel strike /
    toe-off; ``min_stance_s``, ``min_swing_s``: shorter phases are noise (s); ``cutoff_hz``, ``order``: low-pass
    of a belt's force before thresholding (Hz; None: raw); ``foot_markers``: {side: heel marker}; ``toe_markers``:
    {side: toe marker}, used when both are in the file, or None (a foot across two plates is then told by its heel
    alone); ``plate_sides``:
    {side: plate number} as a check, or None; ``label_map``: as
    :class:`~loper_analysis.motion.trial_markers.MarkerSettings`; ``rotation_deg``: lab -> model rotation
    (degrees), which fixes the lab's vertical; ``band_n``, ``max_rest_n``: a plate's resting level (N,
    :func:`loper_analysis.gait.grf.resting_level`).
    """

    grf_channels: Mapping[str, str] | None = field(default_factory=lambda: dict(GRF_CHANNELS))
    threshold_on_n: float = THRESHOLD_ON_N
    threshold_off_n: float = THRESHOLD_OFF_N
    min_stance_s: float = MIN_STANCE_S
    min_swing_s: float = MIN_SWING_S
    cutoff_hz: float | None = None
    order: int = ORDER
    foot_markers: Mapping[str, str] | None = field(default_factory=lambda: dict(FOOT_MARKERS))
    toe_markers: Mapping[str, str] | None = field(default_factory=lambda: dict(TOE_MARKERS))
    plate_sides: Mapping[str, int] | None = None
    label_map: Mapping[str, str] | str | os.PathLike | Sequence | None = None
    rotation_deg: tuple[float, float, float] = LAB_TO_MODEL_ROTATION_DEG
    band_n: float = RESTING_BAND_N
    max_rest_n: float = MAX_RESTING_N


def trial_events(
    rec, platforms: list, s: EventSettings, label_map: Mapping[str, str] | Sequence | None = None
) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The event table and the contact table (empty without force platforms) of a recording and its force
    platforms: the plates with the heel markers (named by ``label_map``), or one analog channel per belt whose
    feet the heel markers confirm (as :func:`loper_analysis.stages.events.step.events` describes)."""
    from loper_analysis.gait.contacts import count_flagged

    _check_heel_sides(rec, s, label_map)
    if rec.n_force_platforms:
        table, contacts = _plate_events(rec, platforms, s, label_map)
        log.info("contacts:\n%s", contacts.to_string(index=False))
        table.attrs["n_contacts_flagged"] = count_flagged(contacts["flag"])
        _warn_time_reversed(rec, s, label_map, _plate_stances(contacts))
        return table, contacts
    if not s.grf_channels:
        raise LoperInputError(
            f"{rec.source}: no force platforms (FORCE_PLATFORM:USED is 0 or absent) and no GRF channel configured "
            "(events.grf_channels); cannot detect gait events"
        )
    table = _channel_events(rec, s)
    _check_belt_feet(rec, table, s, label_map)
    table.attrs["n_contacts_flagged"] = 0
    _warn_time_reversed(rec, s, label_map, _belt_stances(table))
    return table, pd.DataFrame(columns=["plate", "contact", "side", "flag"])


def _channel_events(rec, s: EventSettings) -> pd.DataFrame:
    """Events from one named vertical-GRF analog channel per belt of a read C3D."""
    from loper_analysis.filtering import lowpass
    from loper_analysis.gait.events import gait_events

    c3d_path, grf_channels = rec.source, s.grf_channels
    missing = [side for side in SIDES if grf_channels[side] not in rec.analog_labels]
    if missing:
        named = ", ".join(f"{grf_channels[side]!r} (events.grf_channels.{side})" for side in missing)
        raise LoperInputError(
            f"{c3d_path}: no analog channel {named}, and no force platforms (FORCE_PLATFORM:USED is 0 or absent); "
            f"channels present: {', '.join(rec.analog_labels) or 'none'}"
        )
    tables = []
    for side in SIDES:
        fz = rec.force_channel_n(grf_channels[side], f"events.grf_channels.{side}")
        if s.cutoff_hz is not None:
            fz = lowpass(
                fz,
                rec.analog_rate_hz,
                s.cutoff_hz,
                s.order,
                setting="events.grf_cutoff_hz",
                rate_name="ANALOG:RATE",
                source=f"{c3d_path} (analog channel {grf_channels[side]})",
            )
        tables.append(
            gait_events(
                rec.analog_time_s,
                fz,
                side,
                s.threshold_on_n,
                s.threshold_off_n,
                s.min_stance_s,
                s.min_swing_s,
                source=f"{c3d_path} ({grf_channels[side]})",
            )
        )
    return pd.concat(tables, ignore_index=True).sort_values(["time_s", "side"], kind="stable", ignore_index=True)


def _check_heel_sides(rec, s: EventSettings, label_map) -> None:
    """Stop when the heel markers given for the feet (``events.foot_markers``, ``--feet``) lie on the other sides:
    the left heel's mean position relative to the right heel, along the pelvis's right axis (a left pelvis marker
    to its right partner: ASIS, else PSIS), must be negative
    (:func:`loper_analysis.gait.foot_checks.heel_lateral_offset_m`). Not judged (logged) without both heels or
    without a pelvis pair."""
    from loper_analysis.gait.foot_checks import heel_lateral_offset_m
    from loper_analysis.motion.label_matching import side_landmark_indices
    from loper_analysis.motion.marker_names import model_marker_names

    feet = s.foot_markers
    if not feet or not rec.marker_labels:
        return
    source = rec.source
    names = model_marker_names(rec.marker_labels, label_map, source)
    if any(feet[side] not in names for side in SIDES):
        return  # the events say which heel is missing
    pair = None
    for landmark in ("asis", "psis"):
        ends = [side_landmark_indices(names, [landmark], side) for side in SIDES]
        if all(len(e) == 1 for e in ends):
            pair = (ends[0][0], ends[1][0])
            break
    if pair is None:
        log.info("%s: the heel markers' sides are not checked: no left and right ASIS or PSIS marker", source)
        return
    X = rec.markers_m
    offset = heel_lateral_offset_m(
        X[:, names.index(feet["left"])], X[:, names.index(feet["right"])], X[:, pair[0]], X[:, pair[1]]
    )
    pelvis = f"{names[pair[0]]} -> {names[pair[1]]}"
    if not np.isfinite(offset):
        log.info("%s: the heel markers' sides are not checked: no frame holds both heels and %s", source, pelvis)
        return
    log.info(
        "%s: left heel %s %.0f mm from right heel %s along the pelvis's right axis (%s), mean",
        source,
        feet["left"],
        offset * 1000,
        feet["right"],
        pelvis,
    )
    if offset >= 0:
        raise LoperInputError(
            f"{source}: events.foot_markers (--feet) left {feet['left']}, right {feet['right']}: the heel given "
            f"for the left foot lies {offset * 1000:.0f} mm to the right of the one given for the right foot (mean "
            f"over the trial along the pelvis's left-right axis, {pelvis}); a left heel lies left of the right one. "
            f"Give each foot its own heel marker (here perhaps left {feet['right']}, right {feet['left']})"
        )


#: Contact flags whose foot and whole contact are known: their ends are toe-offs (as the time-direction check reads
#: them), whether or not they give events.
_WHOLE_CONTACT_FLAGS = ("ok", "off_plate", "wrong_belt")


def _plate_stances(contacts: pd.DataFrame) -> dict[str, list[tuple[float, float]]]:
    """{side: [(start, end) s]} of the force plates' foot contacts with a known foot, a foot across plates as one;
    under ``"either"`` the contacts no heel stood in at their start (``no_foot``), of one foot still unknown."""
    out: dict[str, list[tuple[float, float]]] = {side: [] for side in SIDES}
    unknown = contacts[contacts["flag"] == "no_foot"]
    out["either"] = [(float(a), float(b)) for a, b in zip(unknown["start_s"], unknown["end_s"])]
    rows = contacts[contacts["side"].isin(SIDES) & contacts["flag"].isin(_WHOLE_CONTACT_FLAGS)]
    if "foot_contact" in rows.columns:
        key = rows["foot_contact"].where(rows["foot_contact"] >= 0, -1 - np.arange(len(rows)))
    else:
        key = pd.Series(np.arange(len(rows)), index=rows.index)
    for (_, side), group in rows.groupby([key, rows["side"]], sort=True):
        out[side].append((float(group["start_s"].min()), float(group["end_s"].max())))
    return out


def _belt_stances(table: pd.DataFrame) -> dict[str, list[tuple[float, float]]]:
    """{side: [(heel strike, next toe-off) s]} of the belts' event table."""
    out: dict[str, list[tuple[float, float]]] = {side: [] for side in SIDES}
    for side in SIDES:
        mine = table[table["side"] == side].sort_values("time_s", kind="stable")
        start = None
        for event, time in zip(mine["event"], mine["time_s"]):
            if event == "heel_strike":
                start = float(time)
            elif event == "toe_off" and start is not None:
                out[side].append((start, float(time)))
                start = None
    return out


def _toe_indices(names: list[str], s: EventSettings, side: str) -> list[int]:
    """Indices of a foot's toe markers: ``toe_markers`` when both are in the file, else the names that spell a toe
    or a first or fifth metatarsal head of that side."""
    from loper_analysis.motion.label_matching import side_landmark_indices

    if s.toe_markers and all(s.toe_markers[k] in names for k in SIDES):
        return [names.index(s.toe_markers[side])]
    return side_landmark_indices(names, ["toe", "mt1", "mt5"], side)


def _warn_time_reversed(rec, s: EventSettings, label_map, stances: dict[str, list[tuple[float, float]]]) -> None:
    """Warn when the trial's frames seem stored in reverse time: in most of its foot contacts the toe has risen
    more than the heel at the contact's end, where a foot walking forward leaves the ground toe last
    (:func:`loper_analysis.gait.foot_checks.toe_off_heel_lead_m`). A warning, not a stop: a foot that leaves the
    ground flat (the margin is a few centimetres) should not refuse a trial. Not judged (logged) without a toe
    marker of each foot or a contact with both markers at its end."""
    from loper_analysis.gait.foot_checks import lower_foot, toe_off_heel_lead_m
    from loper_analysis.motion.marker_names import model_marker_names
    from loper_analysis.motion.markers import lab_up

    feet, source = s.foot_markers, rec.source
    if not feet or not rec.marker_labels:
        return
    names = model_marker_names(rec.marker_labels, label_map, source)
    toes = {side: _toe_indices(names, s, side) for side in SIDES}
    if any(feet[side] not in names or not toes[side] for side in SIDES):
        log.info("%s: the time direction is not checked: no heel and toe marker of each foot", source)
        return
    up = lab_up(s.rotation_deg)
    heel = {side: rec.markers_m[:, names.index(feet[side]), :] @ up for side in SIDES}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a frame without any toe marker: NaN
        toe = {side: np.nanmean(rec.markers_m[:, toes[side], :] @ up, axis=1) for side in SIDES}
    mine = {side: list(stances[side]) for side in SIDES}
    for start, end in stances.get("either", []):  # the standing foot: the one whose toe is the lower
        side = lower_foot(rec.time_s, toe, start, end)
        if side is not None:
            mine[side].append((start, end))
    leads = [toe_off_heel_lead_m(rec.time_s, heel[side], toe[side], mine[side]) for side in SIDES]
    lead = np.concatenate(leads)
    lead = lead[np.isfinite(lead)]
    if not lead.size:
        log.info("%s: the time direction is not checked: no foot contact with its heel and toe seen at its end", source)
        return
    median_mm, n_back = float(np.median(lead)) * 1000, int((lead < 0).sum())
    log.info(
        "%s: at the end of its %d foot contact(s) the heel had risen %.0f mm more than the toe (median)",
        source,
        lead.size,
        median_mm,
    )
    if median_mm < 0:
        warnings.warn(
            f"{source}: time seems to run backwards in this file: {n_back} of its {lead.size} foot contact(s) end "
            f"with the toe risen more than the heel (by {-median_mm:.0f} mm, median), as a landing does; a foot "
            "walking forward leaves the ground toe last. Are the frames stored in reverse order (a trial exported "
            "backwards)? Its events, strides and every result from them would run backwards too; export the trial "
            "forward",
            stacklevel=2,
        )


#: Fewest stances of a belt, with both heels seen at mid-stance, that can confirm the belt's foot.
MIN_JUDGED_STANCES = 3
#: A belt is taken for the other foot's when its own heel was the lower in at most this fraction of its
#: stances; between it and 1 - it the belt's foot is unclear (a warning).
SWAPPED_BELT_FRACTION = 0.25


def _check_belt_feet(rec, table: pd.DataFrame, s: EventSettings, label_map) -> None:
    """Confirm from the heel markers that each belt channel carries the foot it is named for.

    Stops when a belt's stances are the other foot's (channels swapped, or both naming one belt); warns when
    the heel markers cannot tell (missing markers, too few stances, a mixed verdict).
    """
    from loper_analysis.gait.events import stance_heels
    from loper_analysis.motion.marker_names import model_marker_names
    from loper_analysis.motion.markers import lab_up

    source, grf_channels, foot_markers = rec.source, s.grf_channels, s.foot_markers
    keys = {side: f"events.grf_channels.{side}" for side in SIDES}
    if not foot_markers or not rec.marker_labels:
        warnings.warn(
            f"{source}: the belts' feet ({', '.join(f'{keys[side]} {grf_channels[side]}' for side in SIDES)}) "
            "could not be confirmed: no heel markers (events.foot_markers) in the file",
            stacklevel=2,
        )
        return
    names = model_marker_names(rec.marker_labels, label_map, source)
    missing = [foot_markers[side] for side in SIDES if foot_markers[side] not in names]
    if missing:
        warnings.warn(
            f"{source}: the belts' feet could not be confirmed: heel marker(s) {', '.join(missing)} "
            "(events.foot_markers) not in the file",
            stacklevel=2,
        )
        return
    up = lab_up(s.rotation_deg)
    heights = {side: rec.markers_m[:, names.index(foot_markers[side]), :] @ up for side in SIDES}
    table.attrs["source"] = source
    stances = stance_heels(table, rec.time_s, heights)
    judged = stances[np.isfinite(stances["own_heel_lower_m"])]
    for side in SIDES:
        other = "right" if side == "left" else "left"
        mine = judged[judged["side"] == side]
        n, own = len(mine), int(mine["own_heel_lower"].sum())
        if n < MIN_JUDGED_STANCES:
            warnings.warn(
                f"{source}: the {side} belt's foot ({keys[side]} {grf_channels[side]}) could not be "
                f"confirmed: {n} stance(s) with both heels seen at mid-stance (at least "
                f"{MIN_JUDGED_STANCES} needed)",
                stacklevel=2,
            )
        elif own <= SWAPPED_BELT_FRACTION * n:
            raise LoperInputError(
                f"{source}: {keys[side]}: channel {grf_channels[side]} does not carry the {side} foot: in "
                f"{n - own} of its {n} stances the {other} heel ({foot_markers[other]}) was the lower at "
                f"mid-stance (by {mine['own_heel_lower_m'].median() * -1000:.0f} mm, median); are the belts' "
                f"channels swapped (events.grf_channels: {{left: {grf_channels['left']}, "
                f"right: {grf_channels['right']}}})?"
            )
        elif own < (1 - SWAPPED_BELT_FRACTION) * n:
            warnings.warn(
                f"{source}: the {side} belt's foot ({keys[side]} {grf_channels[side]}) is unclear: its "
                f"own heel ({foot_markers[side]}) was the lower at mid-stance in {own} of {n} stances",
                stacklevel=2,
            )
    log.info(
        "belts' feet: own heel the lower at mid-stance in %s",
        ", ".join(
            f"{int(judged.loc[judged['side'] == side, 'own_heel_lower'].sum())} of "
            f"{int((judged['side'] == side).sum())} {side} stances"
            for side in SIDES
        ),
    )


def _plate_events(rec, platforms: list, s: EventSettings, label_map) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Events and the contact table from the force platforms and the heel markers of a read C3D.

    The vertical is the lab's up direction that ``rotation_deg`` turns into the model's +Y
    (:func:`loper_analysis.motion.markers.lab_up`: lab +Z for the default -90 deg about X, +Y for a Y-up lab
    with no rotation); plates whose corners run either way round are accepted, a plate more than 45 deg
    from level is refused naming the file, the plate and ``markers.lab_to_model_rotation_deg``.
    """
    from loper_analysis.gait.contacts import PlateForce, contact_events, foot_contacts
    from loper_analysis.gait.grf import plates_loads, vertical_loads
    from loper_analysis.motion.marker_names import model_marker_names, require_model_markers
    from loper_analysis.motion.markers import MODEL_UP, lab_up, rotate_markers

    source = rec.source
    foot_markers, rotation_deg = s.foot_markers, s.rotation_deg
    if not foot_markers:
        raise LoperInputError(f"{source}: force platforms need the heel marker of each foot (events.foot_markers)")
    names = model_marker_names(rec.marker_labels, label_map, source)
    require_model_markers(names, [foot_markers[side] for side in SIDES], source, rec.marker_labels)
    up = lab_up(rotation_deg)
    each = plates_loads(platforms, 20.0, s.band_n, s.max_rest_n, up, source)  # as grf.plate_vertical_loads
    loads = vertical_loads(each, rotation_deg)
    plates = [
        PlateForce(n, loads.time_s, loads.vertical_n[:, i], loads.corners_m[i], rotate_markers(p.cop_m, rotation_deg))
        for i, (n, p) in enumerate(zip(loads.numbers, each))
    ]
    heels = {side: rotate_markers(rec.markers_m[:, names.index(foot_markers[side]), :], rotation_deg) for side in SIDES}
    toes = None
    if s.toe_markers and all(s.toe_markers[side] in names for side in SIDES):
        toes = {
            side: rotate_markers(rec.markers_m[:, names.index(s.toe_markers[side]), :], rotation_deg) for side in SIDES
        }
    elif s.toe_markers:
        log.info(
            "%s: no toe markers %s: a foot across two plates is told by its heel alone",
            source,
            " and ".join(s.toe_markers[side] for side in SIDES),
        )
    # corners and heels are in the model frame, whose up is +Y
    contacts = foot_contacts(
        plates,
        rec.time_s,
        heels,
        toes_m=toes,
        plate_sides=s.plate_sides,
        threshold_on_n=s.threshold_on_n,
        threshold_off_n=s.threshold_off_n,
        min_stance_s=s.min_stance_s,
        min_swing_s=s.min_swing_s,
        source=source,
        up=MODEL_UP,
    )
    return contact_events(contacts), contacts
