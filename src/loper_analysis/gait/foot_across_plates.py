"""A foot across force plates: the contacts one foot makes on several plates at once, joined.

* :func:`join_feet` - a ``no_foot`` or ``off_plate`` contact (:mod:`loper_analysis.gait.contact_flags`) given
  to the foot whose heel stands on an overlapping ``ok`` contact's plate and whose toe (or heel) is on this
  plate at its start probe, the other foot not on it; the ``ok`` contacts of one foot loaded at once grouped
  into one foot contact (heel strike at the first plate's loading, toe-off at the last plate's unloading:
  :func:`loper_analysis.gait.contacts.contact_events`).

Time in s, positions in m (markers and plate corners in one frame). ``docs/events.md`` explains the rules.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.constants import SIDES
from loper_analysis.gait.contact_flags import ContactScene, on_plate, positions_at
from loper_analysis.gait.plate_geometry import plate_offsets

__all__ = ["join_feet"]

#: Flags of a contact no heel explains by standing on its plate: another plate's contact of the same foot may.
_JOINABLE = {"no_foot", "off_plate"}


def _foot_on(scene: ContactScene, side: str, k: int, when: float) -> bool:
    """Whether the toe or the heel of ``side`` is on plate ``k`` at ``when`` (s); False without toe markers."""
    if scene.toes_m is None:
        return False
    xyz = np.vstack(
        [positions_at(scene.marker_time_s, m[side], np.array([when])) for m in (scene.toes_m, scene.heels_m)]
    )
    return bool(on_plate(scene, *plate_offsets(xyz, scene.corners_m[k], scene.vertical_axis, up=scene.up)).any())


def _overlap(a: dict, b: dict) -> bool:
    """Whether contacts ``a`` and ``b`` (rows) are loaded at once, on different plates."""
    return a["plate"] != b["plate"] and a["start_s"] < b["end_s"] and b["start_s"] < a["end_s"]


def join_feet(rows: list[dict], scene: ContactScene) -> list[dict]:
    """The rows (of :func:`loper_analysis.gait.contacts.foot_contacts`) with the contacts of one foot on several
    plates joined: a ``no_foot`` or ``off_plate`` contact made ``ok`` for the foot whose heel stands on an
    overlapping ``ok`` contact's plate and whose toe (or heel) is on this plate at its start probe, the other foot
    not on it; ``_group`` set (the row's foot contact)."""
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
