"""Parameters of a C3D file as ezc3d returns them: values, text, rates and events.

Text parameters (``LABELS``, ``UNITS``, ``EVENT:CONTEXTS``, ...) are plain
bytes in the file, in no declared encoding. ezc3d 1.7.2 hands them to Python
with the bytes that are not UTF-8 kept as lone surrogates (``'mm/s\\udcb2'``
for the Latin-1 ``mm/s²``); such a string cannot be encoded again (OpenSim's
wrappers and the TSV writer refuse it). :func:`decode_text` turns the
original bytes back into text: UTF-8 when they are valid UTF-8, Latin-1
(every byte one character) otherwise.

Events (:func:`read_events`) come from ``EVENT:CONTEXTS``, ``EVENT:LABELS``
and ``EVENT:TIMES`` (one (minutes, seconds) pair per event, time =
minutes * 60 + seconds, on the same clock as the frames: frame ``f``
(0-based, counted from the start of the capture) is at ``f / POINT:RATE``).
``EVENT:TIMES`` is read in both layouts found in files: a (2, n) array and a
flat list of 2n numbers (minutes and seconds alternating).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError

__all__ = [
    "EVENT_COLUMNS",
    "decode_text",
    "param_float",
    "param_strings",
    "param_value",
    "read_events",
]

#: Columns of the event table of :func:`read_events`.
EVENT_COLUMNS: tuple[str, ...] = ("context", "label", "time_s")


def decode_text(value) -> str:
    """A C3D text value as ``str``: the bytes as UTF-8 if valid, else as Latin-1; edge blanks stripped.

    Accepts ``bytes`` or the ``str`` ezc3d returns (non-UTF-8 bytes as lone
    surrogates, ``surrogateescape``).
    """
    if isinstance(value, bytes):
        raw = value
    else:
        text = str(value)
        try:
            return text.encode("utf-8").decode("utf-8").strip()
        except UnicodeEncodeError:
            raw = text.encode("utf-8", "surrogateescape")
    try:
        return raw.decode("utf-8").strip()
    except UnicodeDecodeError:
        return raw.decode("latin-1").strip()


def param_value(params, group: str, name: str):
    """The ``value`` of GROUP:NAME in ezc3d's parameter dict, or None when absent."""
    try:
        return params[group][name]["value"]
    except KeyError:
        return None


def param_strings(params, group: str, name: str) -> list[str]:
    """GROUP:NAME joined with NAME2, NAME3, ... (ezc3d splits more than 255 entries), decoded and stripped."""
    out: list[str] = []
    for key in [name] + [f"{name}{k}" for k in range(2, 100)]:
        value = param_value(params, group, key)
        if value is None:
            if key != name:
                break
            continue
        out.extend(decode_text(v) for v in value)
    return out


def param_float(params, group: str, name: str, source: str) -> float:
    """First value of GROUP:NAME as a float; refuses absence and non-positive values."""
    value = param_value(params, group, name)
    try:
        rate = float(np.asarray(value, dtype=float).ravel()[0])
    except (TypeError, ValueError, IndexError):
        raise LoperInputError(f"{source}: {group}:{name} not declared") from None
    if not math.isfinite(rate) or rate <= 0:
        raise LoperInputError(f"{source}: {group}:{name} must be a positive number, got {rate:g}")
    return rate


def _event_times(value, source: str) -> np.ndarray:
    """Seconds (n,) from EVENT:TIMES as (2, n) or as a flat (2n,) list of (minutes, seconds) pairs."""
    try:
        times = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise LoperInputError(f"{source}: EVENT:TIMES is not numeric: {value!r}") from None
    if times.ndim == 1 and times.size % 2 == 0:
        times = times.reshape(2, -1, order="F")  # m0, s0, m1, s1, ...
    if times.ndim != 2 or times.shape[0] != 2:
        raise LoperInputError(
            f"{source}: EVENT:TIMES must hold (minutes, seconds) pairs as (2, n) or 2n values, got shape {times.shape}"
        )
    if not np.all(np.isfinite(times)):
        raise LoperInputError(f"{source}: EVENT:TIMES holds non-finite values")
    return times[0] * 60.0 + times[1]


def read_events(params, source: str) -> pd.DataFrame:
    """The events of a C3D file, in file order.

    Parameters
    ----------
    params : dict
        ezc3d's ``c3d["parameters"]``.
    source : str
        The file (for messages).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`EVENT_COLUMNS`: ``context`` (e.g. ``Left``) and
        ``label`` (e.g. ``Foot Strike``) as str, ``""`` when the file gives
        none, and ``time_s`` (float, s, minutes * 60 + seconds). ``EVENT:USED``
        limits the count when present; without ``EVENT:TIMES`` the table is
        empty.

    Raises
    ------
    LoperInputError
        ``EVENT:TIMES`` not numeric, non-finite, or not of shape (2, n) or
        (2n,); ``EVENT:USED`` larger than the number of times.
    """
    value = param_value(params, "EVENT", "TIMES")
    times = np.zeros(0) if value is None else _event_times(value, source)
    used = param_value(params, "EVENT", "USED")
    n = times.size
    if used is not None and np.size(used):
        n = int(np.asarray(used, dtype=float).ravel()[0])
        if not 0 <= n <= times.size:
            raise LoperInputError(f"{source}: EVENT:USED = {n} but EVENT:TIMES holds {times.size} time(s)")
    contexts = (param_strings(params, "EVENT", "CONTEXTS") + [""] * n)[:n]
    labels = (param_strings(params, "EVENT", "LABELS") + [""] * n)[:n]
    return pd.DataFrame(
        {
            "context": pd.Series(contexts, dtype=object),
            "label": pd.Series(labels, dtype=object),
            "time_s": times[:n].astype(float),
        }
    )
