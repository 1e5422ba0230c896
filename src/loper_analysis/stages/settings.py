"""Every stage's settings from the validated configuration, each built by its own stage's reader.

A stage's reader is ``loper_analysis.stages.<name>.settings``: ``NEEDS``,
the names of the stages whose settings it takes (never re-reading their
keys), and ``read_settings(config, **needs)``, which reads the stage's own
keys. ``study`` is the study's own reader (the trial design, the seed, the
subject sheet and the raw folder). :func:`stage_settings` builds one stage's
settings and, first, those it needs.
"""

from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import Any

from loper_analysis.config_sections import SUBSECTIONS
from loper_analysis.errors import LoperInputError

__all__ = ["stage_settings"]


def stage_settings(config: Mapping, name: str) -> Any:
    """The settings of stage ``name`` (``"study"`` for the study's) from a validated configuration.

    Raises
    ------
    LoperInputError
        A key a reader needs is missing from ``config`` (named with its section, and the stage that reads it),
        or a value the settings refuse (naming the key).
    """
    return _built(config, name, {}, ())


class _Keys(Mapping):
    """A config (or one of its sections) seen by one stage's reader: a missing key is named with its section
    and the reader; a section comes back seen the same way, other values as they are."""

    def __init__(self, data: Mapping, path: tuple[str, ...], reader: str):
        self._data, self._path, self._reader = data, path, reader

    def __getitem__(self, key: str) -> Any:
        if key not in self._data:
            name = ".".join((*self._path, key))
            raise LoperInputError(f"config: key '{name}' missing: the {self._reader} settings read it")
        value = self._data[key]
        path = (*self._path, key)
        if isinstance(value, Mapping) and (not self._path or ".".join(path) in SUBSECTIONS):  # a section
            return _Keys(value, path, self._reader)
        return value  # deeper mappings are values

    def __iter__(self):
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)


def _built(config: Mapping, name: str, built: dict[str, Any], path: tuple[str, ...]) -> Any:
    if name in path:
        raise RuntimeError(f"settings readers need each other in a loop: {' -> '.join((*path, name))}")
    if name not in built:
        reader = importlib.import_module(f"loper_analysis.stages.{name}.settings")
        needs = {need: _built(config, need, built, (*path, name)) for need in reader.NEEDS}
        built[name] = reader.read_settings(_Keys(config, (), name), **needs)
    return built[name]
