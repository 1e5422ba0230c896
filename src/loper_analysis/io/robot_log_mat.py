"""Robot logs exported from MATLAB (.mat), read into the ``loper-log 1`` frame of :mod:`loper_analysis.io.robot_log`."""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError
from loper_analysis.io.robot_log import COLUMNS, FORMAT_NAME, SHANK_COLUMNS, validated_log
from loper_analysis.timing import timed_io

__all__ = ["MAT_OPTIONAL", "read_robot_log_mat"]

#: Columns a .mat export may leave out (mapped to None): they are then zeros.
MAT_OPTIONAL: tuple[str, ...] = ("sync_v", "perturbation", "safety_state")


@timed_io
def read_robot_log_mat(
    path: str | os.PathLike,
    column_map: Mapping[str, str | None],
    sample_rate_hz: float,
    time_scale: float = 1.0,
) -> tuple[pd.DataFrame, dict]:
    """Read a robot log exported from MATLAB (.mat, version 4 to 7.2).

    Parameters
    ----------
    path : str or path-like
        The .mat file (read with :func:`scipy.io.loadmat`).
    column_map : mapping of str to str or None
        Our column (:data:`COLUMNS`) -> name of the variable in the .mat.
        Every column must be mapped, except that ``time_s`` may be absent or
        None (then ``time_s = arange(n) / sample_rate_hz``) and ``sync_v``,
        ``perturbation`` and ``safety_state`` may map to None (then zeros).
        A robot with a second rod at the shank also maps its load cell's
        :data:`~loper_analysis.io.robot_log.SHANK_COLUMNS` (both, or neither:
        absent or None).
        Variables are numeric vectors of equal length n, stored as (n,),
        (n, 1) or (1, n).
    sample_rate_hz : float
        Sample rate of the export (Hz).
    time_scale : float, default 1.0
        Factor from the time variable's unit to seconds (0.001 for ms).

    Returns
    -------
    frame : pandas.DataFrame
        Shape (n, 8), or (n, 10) with the shank rod's columns, as from :func:`read_robot_log`.
    metadata : dict
        ``format``, ``sample_rate_hz`` (float, Hz) and ``source`` (the path).

    Raises
    ------
    LoperInputError
        On a bad map, an unreadable file, a missing or non-vector variable,
        unequal lengths, or any check of :func:`read_robot_log`.
    """
    from scipy.io import loadmat

    path = Path(path)
    source = str(path)
    rate = positive("sample_rate_hz", sample_rate_hz)
    try:
        scale = float(time_scale)
    except (TypeError, ValueError):
        scale = math.nan
    if not math.isfinite(scale) or scale <= 0:
        raise LoperInputError(f"time_scale must be a positive number, got {time_scale!r}")
    columns = _mapped_columns(column_map)

    try:
        contents = loadmat(path)
    except NotImplementedError as exc:  # MATLAB v7.3 (HDF5)
        raise LoperInputError(f"{source}: cannot read .mat file ({exc}); save it with -v7 or older") from exc
    except (OSError, ValueError, TypeError) as exc:
        raise LoperInputError(f"{source}: cannot read .mat file ({exc})") from exc
    available = sorted(k for k in contents if not k.startswith("__"))

    vectors: dict[str, np.ndarray] = {}
    for col in columns:
        var = column_map.get(col)
        if var is None:
            continue
        if var not in contents:
            raise LoperInputError(
                f"{source}: variable '{var}' (for column '{col}') not found; variables in the file: "
                f"{', '.join(available) or 'none'}"
            )
        arr = np.asarray(contents[var])
        if arr.ndim > 2 or (arr.ndim == 2 and min(arr.shape) > 1):
            raise LoperInputError(
                f"{source}: variable '{var}' (for column '{col}') has shape {arr.shape}; expected a vector "
                f"(n,), (n, 1) or (1, n)"
            )
        if arr.dtype.kind not in "biuf":
            raise LoperInputError(
                f"{source}: variable '{var}' (for column '{col}') is not real numeric (dtype {arr.dtype})"
            )
        vectors[col] = arr.reshape(-1).astype(np.float64)
    lengths = {column_map[c]: len(v) for c, v in vectors.items()}
    if len(set(lengths.values())) > 1:
        listed = ", ".join(f"{var} {n}" for var, n in lengths.items())
        raise LoperInputError(f"{source}: variables have unequal lengths: {listed}")
    n = next(iter(lengths.values()))
    if "time_s" in vectors:
        vectors["time_s"] = vectors["time_s"] * scale
    else:
        vectors["time_s"] = np.arange(n) / rate
    for col in MAT_OPTIONAL:
        vectors.setdefault(col, np.zeros(n))
    frame = validated_log(pd.DataFrame({c: vectors[c] for c in columns}), rate, source)
    return frame, {"format": FORMAT_NAME, "sample_rate_hz": rate, "source": source}


def _mapped_columns(column_map) -> tuple[str, ...]:
    """The log's columns a .mat ``column_map`` maps (:data:`COLUMNS`, and the shank rod's when mapped), checked."""
    if not isinstance(column_map, Mapping):
        raise LoperInputError(f"column_map must be a mapping column -> .mat variable, got {type(column_map).__name__}")
    known = (*COLUMNS, *SHANK_COLUMNS)
    unknown = [str(c) for c in column_map if c not in known]
    if unknown:
        raise LoperInputError(f"column_map: unknown column(s) {', '.join(unknown)}; columns are {', '.join(known)}")
    shank = [c for c in SHANK_COLUMNS if column_map.get(c) is not None]
    if len(shank) == 1:
        other = next(c for c in SHANK_COLUMNS if c not in shank)
        raise LoperInputError(
            f"column_map: column '{shank[0]}' is mapped but '{other}' is not: a second rod's load cell needs both"
        )
    columns = (*COLUMNS, *SHANK_COLUMNS) if shank else COLUMNS
    unmapped = [c for c in COLUMNS if c != "time_s" and c not in column_map]
    if unmapped:
        raise LoperInputError(f"column_map: column(s) {', '.join(unmapped)} not mapped to a .mat variable")
    for col, var in column_map.items():
        if var is None:
            if col != "time_s" and col not in (*MAT_OPTIONAL, *SHANK_COLUMNS):
                raise LoperInputError(
                    f"column_map: column '{col}' must map to a .mat variable (only time_s, "
                    f"{', '.join(MAT_OPTIONAL)} may be None)"
                )
        elif not isinstance(var, str) or not var:
            raise LoperInputError(f"column_map: variable of column '{col}' must be a name or None, got {var!r}")
    return columns
