"""The configuration's sections are named after the stages that read them; a configuration written in the
former layout is read once through :func:`translated`, which moves each of its keys to its place now and says so.

========================================  =====================================
former key                                its place now
========================================  =====================================
``trials.*``                              ``study.*``
``filter.*``                              ``markers.filter.*``
``markers.static_duration_s``,            ``model.static_duration_s``,
``markers.static_max_motion_rms_m``       ``model.static_max_motion_rms_m``
``opensim.generic_model``, ``scale_setup``,  ``model.*``
``segment_bodies``,
``brace_attachment_fraction``,
``scale_factor_range``
every other ``opensim.*``                 ``ik.*``
``identification.*``                      ``impedance.*``
``ik.accuracy``, ``opensim.accuracy``     ``ik.tree_step_tolerance`` and
                                          ``ik.opensim_accuracy``, both
========================================  =====================================

The former ``accuracy`` was both the tree solver's step tolerance and OpenSim's solver's accuracy; its value goes
to both keys, so a former file is read with the meaning it had.
"""

from __future__ import annotations

from collections.abc import MutableMapping

__all__ = ["MODEL_KEYS", "MOVED_SECTIONS", "SPLIT_KEYS", "SUBSECTIONS", "new_place", "new_places", "translated"]

#: Sections inside a stage's section (dotted): a stage's part with keys of its own.
SUBSECTIONS: tuple[str, ...] = ("markers.filter",)
#: Former sections that moved whole: former name -> its place now (a dotted path).
MOVED_SECTIONS: dict[str, str] = {"trials": "study", "filter": "markers.filter", "identification": "impedance"}
#: Keys of the former ``opensim`` section that are the model stage's (the others are the IK's).
MODEL_KEYS: tuple[str, ...] = (
    "generic_model",
    "scale_setup",
    "segment_bodies",
    "brace_attachment_fraction",
    "scale_factor_range",
)
#: Keys of the former ``markers`` section that are the model stage's.
_MARKERS_TO_MODEL = ("static_duration_s", "static_max_motion_rms_m")
#: Former keys of two meanings (dotted, at their place after the sections' moves) -> the keys, one per meaning,
#: that each take the former value.
SPLIT_KEYS: dict[str, tuple[str, ...]] = {"ik.accuracy": ("ik.tree_step_tolerance", "ik.opensim_accuracy")}


def new_place(section: str, key: str) -> str:
    """The place now (dotted) of key ``key`` of the former section ``section``."""
    if section == "opensim":
        return f"{'model' if key in MODEL_KEYS else 'ik'}.{key}"
    if section == "markers" and key in _MARKERS_TO_MODEL:
        return f"model.{key}"
    return f"{MOVED_SECTIONS[section]}.{key}"


def new_places(section: str, key: str) -> tuple[str, ...]:
    """The places now (dotted) of key ``key`` of the former section ``section``: one, or a split key's several."""
    place = new_place(section, key)
    return SPLIT_KEYS.get(place, (place,))


def _move(config: MutableMapping, old: str, places: tuple[str, ...], value) -> str:
    """Put ``value`` at each of ``places``; the move as said, ``"old -> new"`` (``"old -> a and b"``)."""
    for place in places:
        _put(config, place, value)
    return f"{old} -> {' and '.join(places)}"


def _put(config: MutableMapping, path: str, value) -> None:
    *parents, last = path.split(".")
    node = config
    for name in parents:
        if not isinstance(node.get(name), MutableMapping):
            node[name] = {}
        node = node[name]
    node[last] = value


def translated(config: MutableMapping) -> list[str]:
    """Move every key of the former layout in ``config`` to its place now, in place (a moved key wins over the
    value at its new place: it was set later or by the user), a split key's value to each of its keys
    (:data:`SPLIT_KEYS`); the moves made, ``"old -> new"`` (``"old -> a and b"``), in order."""
    moves = []
    for section in (*MOVED_SECTIONS, "opensim"):
        values = config.get(section)
        if not isinstance(values, MutableMapping):
            continue
        del config[section]
        for key, value in values.items():
            moves.append(_move(config, f"{section}.{key}", new_places(section, key), value))
    markers = config.get("markers")
    if isinstance(markers, MutableMapping):
        for key in _MARKERS_TO_MODEL:
            if key in markers:
                moves.append(_move(config, f"markers.{key}", (new_place("markers", key),), markers.pop(key)))
    for old, places in SPLIT_KEYS.items():
        section, _, key = old.partition(".")
        values = config.get(section)
        if isinstance(values, MutableMapping) and key in values:
            moves.append(_move(config, old, places, values.pop(key)))
    return moves
