"""Robot logs written as a lab's MATLAB export (.mat, version 5), for the tests that read such exports with
:func:`loper_analysis.io.robot_log_mat.read_robot_log_mat`."""

from __future__ import annotations

import io
import os
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import write_bytes
from loper_analysis.io.robot_log import COLUMNS, SHANK_COLUMNS, validated_log

__all__ = ["MAT_HEADER_TEXT", "write_robot_log_mat"]

#: Descriptive text of the .mat header (116 bytes, blank-padded); fixed, so the same log gives the same bytes.
MAT_HEADER_TEXT = "MATLAB 5.0 MAT-file, robot log written by loper-analysis"


def write_robot_log_mat(
    path: str | os.PathLike,
    frame: pd.DataFrame,
    sample_rate_hz: float,
    variable_names: Mapping[str, str] | None = None,
    time_scale: float = 1.0,
) -> Path:
    """Write a robot log as a MATLAB export (.mat, version 5), atomically; returns ``path``.

    Every column becomes one double column vector (n, 1), named by
    ``variable_names`` (our column -> variable; default: the column names);
    ``time_s`` is written divided by ``time_scale`` (0.001: milliseconds). The
    file reads back with :func:`loper_analysis.io.robot_log_mat.read_robot_log_mat` given the same names as
    ``column_map`` and the same ``time_scale``. The header text is fixed
    (:data:`MAT_HEADER_TEXT`, no creation date): the same log gives the same bytes.

    Parameters
    ----------
    path : str or path-like
        Target ``.mat`` file.
    frame : pandas.DataFrame
        Shape (n, 8): the columns :data:`~loper_analysis.io.robot_log.COLUMNS`,
        passing every check of the log format.
    sample_rate_hz : float
        Sample rate (Hz) the time steps must match.
    variable_names : mapping of str to str, optional
        A MATLAB name (letter first, then letters, digits, ``_``; at most 63
        characters) for every column, all different.
    time_scale : float
        Seconds per unit of the written time variable.

    Raises
    ------
    LoperInputError
        A log that fails the format's checks, a bad or incomplete name map, a
        non-positive ``time_scale``, or a failed write; nothing is left behind.
    """
    from scipy.io import savemat

    source = str(path)
    log = validated_log(frame, sample_rate_hz, source)
    names = {c: c for c in COLUMNS} if variable_names is None else dict(variable_names)
    for c in SHANK_COLUMNS:  # a second rod's load cell: written when the log has it and the map names it
        if names.get(c, "") is None or (c in names and c not in log.columns):
            names.pop(c)
    columns = tuple(log.columns)
    missing = [c for c in columns if c not in names]
    unknown = [str(c) for c in names if c not in columns]
    if missing or unknown:
        raise LoperInputError(
            f"{source}: variable_names must name exactly the columns {', '.join(columns)} "
            f"(missing: {', '.join(missing) or 'none'}; unknown: {', '.join(unknown) or 'none'})"
        )
    for col, var in names.items():
        if not isinstance(var, str) or not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,62}", var):
            raise LoperInputError(f"{source}: variable name {var!r} of column '{col}' is not a MATLAB name")
    if len(set(names.values())) != len(names):
        raise LoperInputError(f"{source}: variable_names must be all different, got {sorted(names.values())}")
    scale = positive("time_scale", time_scale, source)
    variables = {names[c]: log[c].to_numpy(dtype=np.float64)[:, np.newaxis] for c in columns}
    variables[names["time_s"]] = variables[names["time_s"]] / scale
    buffer = io.BytesIO()
    savemat(buffer, variables, format="5", oned_as="column")
    data = bytearray(buffer.getvalue())
    data[:116] = MAT_HEADER_TEXT.encode("ascii").ljust(116, b" ")
    return write_bytes(path, bytes(data), "robot log (.mat)")
