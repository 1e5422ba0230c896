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
========================================  =====================================
"""

from __future__ import annotations

from collections.abc import MutableMapping

__all__ = ["MODEL_KEYS", "MOVED_SECTIONS", "SUBSECTIONS", "new_place", "translated"]

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


def new_place(section: str, key: str) -> str:
    """The place now (dotted) of key ``key`` of the former section ``section``."""
    if section == "opensim":
        return f"{'model' if key in MODEL_KEYS else 'ik'}.{key}"
    if section == "markers" and key in _MARKERS_TO_MODEL:
        return f"model.{key}"
    return f"{MOVED_SECTIONS[section]}.{key}"


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
    value at its new place: it was set later or by the user); the moves made, ``"old -> new"``, in order."""
    moves = []
    for section in (*MOVED_SECTIONS, "opensim"):
        values = config.get(section)
        if not isinstance(values, MutableMapping):
            continue
        del config[section]
        for key, value in values.items():
            _put(config, new_place(section, key), value)
            moves.append(f"{section}.{key} -> {new_place(section, key)}")
    markers = config.get("markers")
    if isinstance(markers, MutableMapping):
        for key in _MARKERS_TO_MODEL:
            if key in markers:
                _put(config, new_place("markers", key), markers.pop(key))
                moves.append(f"markers.{key} -> {new_place('markers', key)}")
    return moves
