"""Input checks shared by the whole library.

Every check returns the checked value in its working form (a float, an
array, a list) or raises :class:`~loper_analysis.errors.LoperInputError`
whose message starts with ``source`` (the file, trial or subject the value
came from, when given) and names the field and the offending value.
"""

from __future__ import annotations

import math
import numbers
import re
from collections.abc import Sequence

import numpy as np
import pandas as pd

from loper_analysis.constants import SIDES
from loper_analysis.errors import LoperInputError

__all__ = [
    "where",
    "marker_array",
    "number",
    "positive",
    "integer",
    "side",
    "time_vector",
    "uniform_step_s",
    "signal",
    "finite_vector",
    "finite_rows",
    "require_columns",
    "bool_column",
    "unique_names",
    "generator",
]

_WHITESPACE = re.compile(r"\s")
#: Whitespace other than the plain space (tabs, line breaks, ...).
_NOT_SPACE_WHITESPACE = re.compile(r"[^\S ]")


def where(source: str) -> str:
    """Message prefix naming the source: ``"source: "``, or nothing without a source."""
    return f"{source}: " if source else ""


def number(name: str, value, source: str = "", minimum: float | None = None, maximum: float | None = None) -> float:
    """A finite real number, optionally within ``minimum .. maximum`` (inclusive)."""
    if isinstance(value, bool):
        raise LoperInputError(f"{where(source)}{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise LoperInputError(f"{where(source)}{name} must be a number, got {value!r}") from None
    if not math.isfinite(v) or (minimum is not None and v < minimum) or (maximum is not None and v > maximum):
        bound = ""
        if minimum is not None and maximum is not None:
            bound = f" in {minimum} .. {maximum}"
        elif minimum is not None:
            bound = f" >= {minimum}"
        elif maximum is not None:
            bound = f" <= {maximum}"
        raise LoperInputError(f"{where(source)}{name} must be a finite number{bound}, got {v!r}")
    return v


def positive(name: str, value, source: str = "") -> float:
    """A finite number > 0."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(value, bool) or not math.isfinite(v) or v <= 0:
        raise LoperInputError(f"{where(source)}{name} must be a positive number, got {value!r}")
    return v


def integer(name: str, value, source: str = "", minimum: int | None = None) -> int:
    """An integral number (``3`` or ``3.0``, not ``True``), optionally ``>= minimum``."""
    ok = (
        isinstance(value, numbers.Real)
        and not isinstance(value, bool)
        and math.isfinite(float(value))
        and float(value) == int(value)
    )
    if not ok or (minimum is not None and int(value) < minimum):
        bound = f" >= {minimum}" if minimum is not None else ""
        raise LoperInputError(f"{where(source)}{name} must be an integer{bound}, got {value!r}")
    return int(value)


def side(value: str, source: str = "") -> str:
    """One of :data:`loper_analysis.constants.SIDES`."""
    if value not in SIDES:
        raise LoperInputError(f"{where(source)}side must be one of {SIDES}, got {value!r}")
    return value


def time_vector(time_s, source: str = "", name: str = "time_s", min_count: int = 2, item: str = "sample") -> np.ndarray:
    """A 1-D, finite, strictly increasing time vector (s) of at least ``min_count`` values.

    ``item`` names one element in messages (``sample``, ``frame``, ``row``).
    """
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < min_count:
        raise LoperInputError(f"{where(source)}{name} must be 1-D with >= {min_count} {item}s, got shape {t.shape}")
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        i = int(bad[0])
        raise LoperInputError(f"{where(source)}{name} is not finite at {item} {i}: {float(t[i])!r}")
    step = np.flatnonzero(np.diff(t) <= 0)
    if step.size:
        i = int(step[0]) + 1
        raise LoperInputError(
            f"{where(source)}{name} must increase strictly; {item} {i} ({float(t[i])!r} s) "
            f"follows {float(t[i - 1])!r} s"
        )
    return t


def uniform_step_s(t: np.ndarray, source: str = "", name: str = "time_s", rel_tolerance: float = 1e-6) -> float:
    """The step (s) of an increasing, equally spaced time vector, ``(t[-1] - t[0]) / (n - 1)``.

    Refuses a step that differs from it by more than ``rel_tolerance``.
    """
    step = (t[-1] - t[0]) / (t.size - 1)
    worst = int(np.argmax(np.abs(np.diff(t) - step)))
    if abs(t[worst + 1] - t[worst] - step) > rel_tolerance * step:
        raise LoperInputError(
            f"{where(source)}{name} must be equally spaced; step {t[worst + 1] - t[worst]:.9g} s at row {worst} "
            f"differs from the mean step {step:.9g} s"
        )
    return float(step)


def signal(name: str, values, n: int, source: str = "") -> np.ndarray:
    """Samples along axis 0: shape (n,) or (n, k), like a time vector of ``n`` values."""
    v = np.asarray(values, dtype=float)
    if v.ndim not in (1, 2) or v.shape[0] != n:
        raise LoperInputError(f"{where(source)}{name} must have shape ({n},) or ({n}, k) like time_s, got {v.shape}")
    return v


def finite_vector(name: str, values, source: str = "", min_count: int = 2) -> np.ndarray:
    """A 1-D finite array of at least ``min_count`` samples."""
    a = np.asarray(values, dtype=float)
    if a.ndim != 1:
        raise LoperInputError(f"{where(source)}{name} must be 1-D, got shape {a.shape}")
    if a.size < min_count:
        raise LoperInputError(f"{where(source)}{name} needs >= {min_count} samples, got {a.size}")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise LoperInputError(f"{where(source)}{name} is not finite at sample {bad[0]}: {a[bad[0]]}")
    return a


def finite_rows(name: str, values, width: int, source: str = "") -> tuple[np.ndarray, bool]:
    """A finite (n, width) array from (width,) or (n, width), and whether the input was one row."""
    a = np.asarray(values, dtype=float)
    single = a.ndim == 1
    a2 = np.atleast_2d(a)
    if a2.ndim != 2 or a2.shape[1] != width:
        raise LoperInputError(f"{where(source)}{name} must have shape ({width},) or (n, {width}), got {a.shape}")
    if not np.all(np.isfinite(a2)):
        i = np.argwhere(~np.isfinite(a2))[0]
        raise LoperInputError(f"{where(source)}{name} is not finite at row {i[0]}, column {i[1]}: {a2[tuple(i)]}")
    return np.ascontiguousarray(a2), single


def marker_array(markers_m, source: str = "") -> np.ndarray:
    """Markers as a float array of shape (n_frames, n_markers, 3); another shape is refused naming ``source``."""
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(
            f"{source or 'markers'}: markers_m must have shape (n_frames, n_markers, 3), got {X.shape}"
        )
    return X


def require_columns(table, columns: Sequence[str], source: str = "", what: str = "") -> pd.DataFrame:
    """The table itself when it is a DataFrame holding every one of ``columns``."""
    label = f"{what}: " if what else ""
    if not isinstance(table, pd.DataFrame):
        raise LoperInputError(
            f"{where(source)}{what or 'table'} must be a pandas DataFrame, got {type(table).__name__}"
        )
    missing = [c for c in columns if c not in table.columns]
    if missing:
        raise LoperInputError(f"{where(source)}{label}column(s) {missing} missing")
    return table


#: Accepted spellings of a boolean cell (True/False also match 1/0 and 1.0/0.0, which hash alike).
_BOOLEAN = {True: True, False: False, "True": True, "False": False, "true": True, "false": False}


def bool_column(table: pd.DataFrame, name: str, source: str = "", what: str = "table") -> np.ndarray:
    """A boolean column (bool, 0/1 or the words true/false) as a bool array."""
    col = table[name]
    if col.dtype == bool:
        return col.to_numpy()
    out = np.empty(len(col), dtype=bool)
    for i, value in enumerate(col.to_numpy()):
        try:
            out[i] = _BOOLEAN[value]
        except (KeyError, TypeError):
            raise LoperInputError(
                f"{where(source)}{what}: column {name!r} must be boolean; row {i} holds {value!r}"
            ) from None
    return out


def unique_names(
    names,
    what: str,
    source: str = "",
    max_chars: int | None = None,
    allow_whitespace: bool = True,
    allow_spaces: bool = False,
) -> list[str]:
    """Non-empty, unique strings without leading or trailing blanks (and, if asked, without any whitespace).

    ``allow_whitespace=False`` refuses every whitespace character; with
    ``allow_spaces=True`` as well, plain spaces (U+0020) inside a name are
    accepted (``r heel``) and only other whitespace (tabs, line breaks) is
    refused: the rule of tab-separated formats such as TRC.
    """
    names = list(names)
    inner = _NOT_SPACE_WHITESPACE if allow_spaces else _WHITESPACE
    for name in names:
        bad = not isinstance(name, str) or not name or name != name.strip()
        bad = bad or (max_chars is not None and len(name) > max_chars)
        bad = bad or (not allow_whitespace and bool(inner.search(name)))
        if bad:
            limits = []
            if max_chars is not None:
                limits.append(f"at most {max_chars} characters")
            if allow_whitespace:
                limits.append("leading/trailing blanks")
            elif allow_spaces:
                limits.append("leading/trailing blanks or whitespace other than inner spaces")
            else:
                limits.append("whitespace")
            rule = (
                f"non-empty strings of {limits[0]} without {limits[1]}"
                if len(limits) == 2
                else f"non-empty strings without {limits[0]}"
            )
            raise LoperInputError(f"{where(source)}{what} must be {rule}, got {name!r}")
    duplicated = sorted({n for n in names if names.count(n) > 1})
    if duplicated:
        raise LoperInputError(f"{where(source)}{what} duplicated: {', '.join(duplicated)}")
    return names


def generator(rng, name: str = "rng") -> np.random.Generator:
    """A :class:`numpy.random.Generator` (the source of every random number of a simulation)."""
    if not isinstance(rng, np.random.Generator):
        raise LoperInputError(f"{name} must be a numpy.random.Generator, got {type(rng).__name__}")
    return rng
