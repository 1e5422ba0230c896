"""The robot (LOPER) log: one file format, its reader and its writer.

A robot log is the 1000 Hz record of the treadmill robot, one file per
subject and trial at ``data/raw/{subject}/{trial}.loper.tsv``
. The format, ``loper-log 1``, is UTF-8 text with
tab-separated values::

    # format: loper-log 1
    # sample_rate_hz: 1000
    # trial: steps40                 <- optional free keys, '# key: value'
    # clock: robot
    time_s<TAB>force_desired_n<TAB>force_measured_n<TAB>motor_angle_rad<TAB>...
    0<TAB>0<TAB>0.0312<TAB>0.00104<TAB>...
    0.001<TAB>...

* Header comment lines come first, each ``# key: value``. ``format`` (exactly
  ``loper-log 1``) and ``sample_rate_hz`` are required; any other key is free
  metadata, read back as a string.
* Then one row of column names, which carry their units (:data:`UNITS`):
  exactly :data:`COLUMNS`, in that order, and for a robot with a second rod
  just above the ankle its load cell's :data:`SHANK_COLUMNS` after them (both
  or neither); missing, unknown, duplicated or reordered columns are refused.
* Then one data row per sample: ``time_s`` strictly increasing with steps of
  ``1 / sample_rate_hz`` (each within 1 %); ``force_desired_n`` and
  ``force_measured_n`` (and the shank rod's two forces) finite; ``motor_angle_rad``, ``motor_velocity_rad_s``
  and ``sync_v`` may be ``nan`` (missing) but not infinite; ``perturbation``
  0 or 1; ``safety_state`` one of the codes of :data:`SAFETY_STATES`. At
  least 2 samples.

The writer prints ``time_s`` with ``%.15g``, the other real-valued channels
with ``%.9g`` and the two integer columns as integers, so the same data give
the same bytes. Every check of the reader is applied to the frame before
anything is written (one shared validation, :func:`validated_log`), so nothing invalid is written,
and writing is atomic (a temporary file in the target directory, then
:func:`os.replace`).

Every problem raises :class:`~loper_analysis.errors.LoperInputError` whose
message names the file, and where applicable the column and the sample
(0-based row index of the data, with its time and, for text files, its line
number).
"""

from __future__ import annotations

import io
import math
import numbers
import os
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import write_bytes
from loper_analysis.timing import timed_io

__all__ = [
    "FORMAT_NAME",
    "COLUMNS",
    "SHANK_COLUMNS",
    "UNITS",
    "SAFETY_STATES",
    "TIME_STEP_TOLERANCE",
    "validated_log",
    "log_columns",
    "read_robot_log",
    "write_robot_log",
]

#: Value of the required ``# format:`` header line.
FORMAT_NAME = "loper-log 1"

#: The columns of a robot log, in file order.
COLUMNS: tuple[str, ...] = (
    "time_s",
    "force_desired_n",
    "force_measured_n",
    "motor_angle_rad",
    "motor_velocity_rad_s",
    "sync_v",
    "perturbation",
    "safety_state",
)
#: The load cell of a second rod just above the ankle, after :data:`COLUMNS` in a log that has one: its desired
#: and measured force (N, along the rod, forward positive).
SHANK_COLUMNS: tuple[str, ...] = ("shank_force_desired_n", "shank_force_measured_n")

#: Unit of each column ("1": dimensionless flag or code).
UNITS: dict[str, str] = {
    "time_s": "s",  # robot clock
    "force_desired_n": "N",  # desired interaction force
    "force_measured_n": "N",  # load cell
    "motor_angle_rad": "rad",
    "motor_velocity_rad_s": "rad/s",
    "sync_v": "V",  # sync signal sent to the motion-capture analog input
    "perturbation": "1",  # 0/1 flag
    "safety_state": "1",  # integer code, see SAFETY_STATES
    "shank_force_desired_n": "N",  # a second rod's desired force
    "shank_force_measured_n": "N",  # its load cell
}

#: Safety-state codes of the ``safety_state`` column.
SAFETY_STATES: dict[int, str] = {
    0: "ok",
    1: "limited",  # position/velocity/acceleration (PVA) limiter active
    2: "motor_off_position",
    3: "motor_off_velocity",
    4: "motor_off_torque",
    5: "servo_off_position",
}

#: Largest allowed relative deviation of a time step from ``1 / sample_rate_hz``.
TIME_STEP_TOLERANCE = 0.01

_INT_COLUMNS = ("perturbation", "safety_state")
_FLOAT_COLUMNS = tuple(c for c in COLUMNS if c not in _INT_COLUMNS)
_FORCE_COLUMNS = ("force_desired_n", "force_measured_n", *SHANK_COLUMNS)
_MAY_BE_NAN = ("motor_angle_rad", "motor_velocity_rad_s", "sync_v")
_KEY_PATTERN = re.compile(r"[A-Za-z_][A-Za-z0-9_.\-]*\Z")
_TIME_FORMAT = "%.15g"
_VALUE_FORMAT = "%.9g"


# ---------------------------------------------------------------------------
# shared validation


def _where(source: str, column: str | None, sample: int, time: float | None, line: int | None = None) -> str:
    """Message prefix naming file, column and sample."""
    parts = [f"sample {sample}"]
    detail = []
    if time is not None:
        detail.append(f"t = {time:.9g} s")
    if line is not None:
        detail.append(f"line {line}")
    if detail:
        parts[0] += f" ({', '.join(detail)})"
    if column is not None:
        parts.insert(0, f"column '{column}'")
    return f"{source}: {', '.join(parts)}"


def _percent(value: float) -> str:
    """Signed, 3 significant digits, no exponent (e.g. +20, -50, +99900)."""
    return np.format_float_positional(value, precision=3, fractional=False, trim="-", sign=True)


def _as_float(series: pd.Series, column: str, source: str, time: np.ndarray | None) -> np.ndarray:
    """The column as float64; refuses non-numeric cells, naming the first."""
    if pd.api.types.is_numeric_dtype(series.dtype) and not pd.api.types.is_complex_dtype(series.dtype):
        return series.to_numpy(dtype=np.float64, na_value=np.nan)
    values = series.to_numpy(dtype=object)
    out = np.empty(len(values), dtype=np.float64)
    for i, v in enumerate(values):
        if isinstance(v, numbers.Real) and not isinstance(v, (str, bytes)):
            out[i] = float(v)
        else:
            t = None if time is None else float(time[i])
            raise LoperInputError(f"{_where(source, column, i, t)}: non-numeric value {v!r}")
    return out


def log_columns(names) -> tuple[str, ...]:
    """The columns of a log whose columns are ``names``, in file order: :data:`COLUMNS`, then
    :data:`SHANK_COLUMNS` when ``names`` holds any of them."""
    return (*COLUMNS, *SHANK_COLUMNS) if any(c in SHANK_COLUMNS for c in names) else COLUMNS


def _check_column_names(names: list[str], source: str, where: str) -> None:
    """Refuse duplicated, missing or unknown columns (``where`` prefixes the duplicate message)."""
    duplicated = sorted({c for c in names if names.count(c) > 1})
    if duplicated:
        raise LoperInputError(f"{source}: {where}duplicated column(s) {', '.join(duplicated)}")
    expected = log_columns(names)
    missing = [c for c in expected if c not in names]
    if missing:
        raise LoperInputError(
            f"{source}: missing column(s) {', '.join(missing)}; a robot log has the columns {', '.join(COLUMNS)}, "
            f"and a robot with a second rod at the shank also {' and '.join(SHANK_COLUMNS)}"
        )
    unknown = [c or "''" for c in names if c not in expected]
    if unknown:
        raise LoperInputError(
            f"{source}: unknown column(s) {', '.join(unknown)}; a robot log has exactly the columns "
            f"{', '.join(COLUMNS)} (and, with a second rod at the shank, {' and '.join(SHANK_COLUMNS)})"
        )


def validated_log(
    frame: pd.DataFrame, sample_rate_hz: float, source: str, first_line: int | None = None
) -> pd.DataFrame:
    """Check a robot-log frame; return it normalised.

    The one validation of the format, shared by the TSV reader, the .mat
    reader and the writer.

    Parameters
    ----------
    frame : pandas.DataFrame
        Exactly the columns :data:`COLUMNS` (any order), one row per sample.
    sample_rate_hz : float
        Sample rate (Hz) the time steps must match.
    source : str
        What to name in messages (the file).
    first_line : int, optional
        Line of the text file holding sample 0 (1-based), to name the line
        of a bad sample in messages.

    Returns
    -------
    pandas.DataFrame
        Shape (n, 8), or (n, 10) with :data:`SHANK_COLUMNS`: columns in that order, float64 except
        ``perturbation`` and ``safety_state`` (int64), index ``0..n-1``.
    """
    if not isinstance(frame, pd.DataFrame):
        raise LoperInputError(f"{source}: a robot log must be a pandas DataFrame, got {type(frame).__name__}")
    names = [str(c) for c in frame.columns]
    _check_column_names(names, source, "")
    rate = positive("sample_rate_hz", sample_rate_hz, source)
    n = len(frame)
    if n < 2:
        raise LoperInputError(f"{source}: {n} sample(s); a robot log needs at least 2")

    frame = frame.set_axis(names, axis=1)
    columns = log_columns(names)
    time = _as_float(frame["time_s"], "time_s", source, None)
    data = {"time_s": time}
    for col in columns[1:]:
        data[col] = _as_float(frame[col], col, source, time)

    def fail(column: str, i: int, problem: str):
        line = None if first_line is None else first_line + int(i)
        raise LoperInputError(f"{_where(source, column, int(i), float(time[i]), line)}: {problem}")

    bad = np.flatnonzero(~np.isfinite(time))
    if bad.size:
        fail("time_s", bad[0], f"non-finite time {time[bad[0]]}")
    step = np.diff(time)
    bad = np.flatnonzero(step <= 0)
    if bad.size:
        i = bad[0] + 1
        fail("time_s", i, f"time not strictly increasing (sample {i - 1} is at t = {time[i - 1]:.9g} s)")
    deviation = step * rate - 1.0
    bad = np.flatnonzero(np.abs(deviation) > TIME_STEP_TOLERANCE)
    if bad.size:
        i = bad[0] + 1
        fail(
            "time_s",
            i,
            f"time step {1e3 * step[i - 1]:.6g} ms since sample {i - 1} deviates {_percent(100 * deviation[i - 1])} % "
            f"from 1/sample_rate_hz = {1e3 / rate:.6g} ms (tolerance {100 * TIME_STEP_TOLERANCE:g} %)",
        )
    for col in (c for c in _FORCE_COLUMNS if c in data):
        bad = np.flatnonzero(~np.isfinite(data[col]))
        if bad.size:
            fail(col, bad[0], f"non-finite force {data[col][bad[0]]}")
    for col in _MAY_BE_NAN:
        bad = np.flatnonzero(np.isinf(data[col]))
        if bad.size:
            fail(col, bad[0], f"infinite value {data[col][bad[0]]} (missing samples are nan)")
    pert = data["perturbation"]
    bad = np.flatnonzero((pert != 0) & (pert != 1))
    if bad.size:
        fail("perturbation", bad[0], f"value {pert[bad[0]]:g} is not 0 or 1")
    safety = data["safety_state"]
    known = np.array(sorted(SAFETY_STATES), dtype=np.float64)
    bad = np.flatnonzero(~np.isin(safety, known))
    if bad.size:
        codes = ", ".join(f"{k} {v}" for k, v in SAFETY_STATES.items())
        fail("safety_state", bad[0], f"unknown safety state {safety[bad[0]]:g} (codes: {codes})")

    out = pd.DataFrame({c: data[c] for c in columns if c not in _INT_COLUMNS}, index=pd.RangeIndex(n))
    for col in _INT_COLUMNS:
        out[col] = data[col].astype(np.int64)
    return out[list(columns)]


# ---------------------------------------------------------------------------
# TSV


def _format_rate(rate: float) -> str:
    return _TIME_FORMAT % rate


def write_robot_log(
    path: str | os.PathLike,
    frame: pd.DataFrame,
    sample_rate_hz: float = 1000.0,
    metadata: dict | None = None,
) -> None:
    """Write a robot log (format ``loper-log 1``) atomically.

    Parameters
    ----------
    path : str or path-like
        Target file (``*.loper.tsv``; a missing directory is created). An existing
        file is replaced.
    frame : pandas.DataFrame
        Shape (n, 8) or (n, 10), n >= 2: exactly the columns :data:`COLUMNS` (any order;
        written in :data:`COLUMNS` order), units as in :data:`UNITS`. It must
        pass every check of :func:`read_robot_log`; the index is ignored.
    sample_rate_hz : float, default 1000.0
        Sample rate (Hz), written as the ``sample_rate_hz`` header line; the
        steps of ``time_s`` must match it within 1 %.
    metadata : dict, optional
        Free header keys, written in the given order as ``# key: value``.
        Keys match ``[A-Za-z_][A-Za-z0-9_.-]*``; values are written with
        ``str`` and must be single-line without leading or trailing
        whitespace. ``format`` and ``sample_rate_hz`` may be present (e.g. the
        metadata returned by :func:`read_robot_log`) only if they agree with
        the log.

    Raises
    ------
    LoperInputError
        On invalid data or metadata; then nothing is written (an existing
        file is left as it was).
    """
    path = Path(path)
    source = f"refusing to write {path}"
    rate = positive("sample_rate_hz", sample_rate_hz, source)
    clean = validated_log(frame, rate, source)
    header = [f"# format: {FORMAT_NAME}", f"# sample_rate_hz: {_format_rate(rate)}"]
    if metadata is not None and not isinstance(metadata, Mapping):
        raise LoperInputError(f"{source}: metadata must be a dict of key -> value, got {type(metadata).__name__}")
    for key, value in (metadata or {}).items():
        if not isinstance(key, str) or not _KEY_PATTERN.match(key):
            raise LoperInputError(f"{source}: metadata key {key!r} must match [A-Za-z_][A-Za-z0-9_.-]*")
        text = str(value)
        if key == "format":
            if text != FORMAT_NAME:
                raise LoperInputError(f"{source}: metadata format {text!r} is not {FORMAT_NAME!r}")
            continue
        if key == "sample_rate_hz":
            try:
                agrees = math.isclose(float(value), rate, rel_tol=1e-12)
            except (TypeError, ValueError):
                agrees = False
            if not agrees:
                raise LoperInputError(
                    f"{source}: metadata sample_rate_hz {value!r} disagrees with sample_rate_hz {rate:g}"
                )
            continue
        if "\n" in text or "\r" in text or text != text.strip():
            raise LoperInputError(
                f"{source}: metadata value of {key!r} must be one line without leading or trailing "
                f"whitespace, got {text!r}"
            )
        header.append(f"# {key}: {text}")
    columns = log_columns(clean.columns)
    header.append("\t".join(columns))

    cells = []
    for col in columns:
        values = clean[col].tolist()
        if col in _INT_COLUMNS:
            cells.append([str(v) for v in values])
        else:
            fmt = _TIME_FORMAT if col == "time_s" else _VALUE_FORMAT
            cells.append([fmt % v for v in values])
    text = "\n".join(header) + "\n" + "\n".join("\t".join(row) for row in zip(*cells)) + "\n"
    write_bytes(path, text.encode("utf-8"), "robot log")


def _parse_floats(cells: list[str], column: str, source: str, first_line: int, time: np.ndarray | None):
    try:
        return np.array(cells, dtype=np.float64)
    except ValueError:
        pass
    out = np.empty(len(cells), dtype=np.float64)
    for i, cell in enumerate(cells):
        try:
            out[i] = float(cell)
        except ValueError:
            t = None if time is None else float(time[i])
            raise LoperInputError(
                f"{_where(source, column, i, t, first_line + i)}: non-numeric value {cell!r}"
            ) from None
    return out  # pragma: no cover - numpy and float() disagree


@timed_io
def read_robot_log(path: str | os.PathLike, sample_rate_hz: float | None = None) -> tuple[pd.DataFrame, dict]:
    """Read and check a robot log (format ``loper-log 1``).

    Parameters
    ----------
    path : str or path-like
        The ``*.loper.tsv`` file.
    sample_rate_hz : float, optional
        Expected sample rate (Hz); if given, the file's ``sample_rate_hz``
        header must equal it.

    Returns
    -------
    frame : pandas.DataFrame
        Shape (n, 8) or (n, 10), n >= 2: columns :data:`COLUMNS` (and :data:`SHANK_COLUMNS`; units :data:`UNITS`),
        float64 except ``perturbation`` and ``safety_state`` (int64); index
        ``0..n-1`` is the sample number.
    metadata : dict
        The header in file order: ``format`` (str), ``sample_rate_hz``
        (float, Hz) and every free key (str values).

    Raises
    ------
    LoperInputError
        If the file cannot be read or violates the format; the message names
        the file and, where applicable, the column and the sample (0-based
        data row, its time and its line in the file).
    """
    path = Path(path)
    source = str(path)
    expected = None if sample_rate_hz is None else positive("sample_rate_hz", sample_rate_hz)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise LoperInputError(f"{source}: not a loper log: not UTF-8 text ({exc})") from exc
    except OSError as exc:
        raise LoperInputError(f"{source}: cannot read robot log ({exc})") from exc
    lines = text.splitlines()
    while lines and not lines[-1].strip():
        lines.pop()

    meta: dict = {}
    k = 0
    while k < len(lines) and lines[k].startswith("#"):
        key, sep, value = lines[k][1:].partition(":")
        key, value = key.strip(), value.strip()
        if not sep or not _KEY_PATTERN.match(key):
            if "format" not in meta:
                break  # reported below as not a loper log
            raise LoperInputError(f"{source}: line {k + 1}: header line must be '# key: value', found {lines[k]!r}")
        if key in meta:
            raise LoperInputError(f"{source}: line {k + 1}: header key {key!r} repeated")
        meta[key] = value
        k += 1
    if "format" not in meta:
        raise LoperInputError(f"{source}: not a loper log: no '# format: {FORMAT_NAME}' header line")
    if meta["format"] != FORMAT_NAME:
        raise LoperInputError(f"{source}: unsupported format {meta['format']!r}; this reader reads {FORMAT_NAME!r}")
    if "sample_rate_hz" not in meta:
        raise LoperInputError(f"{source}: no '# sample_rate_hz: ...' header line")
    rate = positive("header sample_rate_hz", meta["sample_rate_hz"], source)
    meta["sample_rate_hz"] = rate
    if expected is not None and not math.isclose(rate, expected, rel_tol=1e-12):
        raise LoperInputError(f"{source}: sample_rate_hz in the file is {rate:g} Hz but {expected:g} Hz was declared")

    if k >= len(lines):
        raise LoperInputError(f"{source}: no column header row after the '#' header lines")
    names = [c.strip() for c in lines[k].split("\t")]
    header_line = k + 1
    _check_column_names(names, source, f"line {header_line}: ")
    columns = log_columns(names)
    if tuple(names) != columns:
        raise LoperInputError(
            f"{source}: line {header_line}: columns in the order {', '.join(names)}; a robot log has them in "
            f"the order {', '.join(columns)}"
        )

    rows = lines[k + 1 :]
    first_line = header_line + 1
    data = _parse_rows(rows, source, first_line, columns)
    frame = validated_log(pd.DataFrame(data), rate, source, first_line)
    return frame, meta


def _parse_rows(
    rows: list[str], source: str, first_line: int, names: tuple[str, ...] = COLUMNS
) -> dict[str, np.ndarray]:
    """Data rows -> one float64 array per column of ``names``; names the first malformed row or cell."""
    width = len(names)
    if rows:  # fast path (C parser); any doubt -> the checking path below
        try:
            table = np.loadtxt(io.StringIO("\n".join(rows)), delimiter="\t", dtype=np.float64, ndmin=2, comments=None)
        except ValueError:
            table = None
        if table is not None and table.shape == (len(rows), width):
            return {col: np.ascontiguousarray(table[:, j]) for j, col in enumerate(names)}
    split = [row.split("\t") for row in rows]
    for i, fields in enumerate(split):
        if len(fields) != width:
            raise LoperInputError(
                f"{_where(source, None, i, None, first_line + i)}: {len(fields)} field(s), expected {width} "
                f"(one per column)"
            )
    columns = list(zip(*split)) if split else [()] * width
    time = _parse_floats(list(columns[0]), "time_s", source, first_line, None)
    data = {"time_s": time}
    for j, col in enumerate(names[1:], start=1):
        data[col] = _parse_floats(list(columns[j]), col, source, first_line, time)
    return data
