"""OpenSim's text formats (TRC markers, MOT/STO coordinates) through OpenSim's own adapters.

TRC (:func:`write_trc`, :func:`read_markers`)
    Written byte for byte as ``opensim.TRCFileAdapter`` writes it (header
    ``DataRate``, ``CameraRate`` = ``DataRate``, ``NumFrames``,
    ``NumMarkers``, ``Units``, ``OrigDataRate``, ``OrigDataStartFrame`` = 0,
    ``OrigNumFrames``; values to 16 significant digits, missing markers as
    ``nan``), but formatted here: the adapter needs OpenSim imported (0.7 s
    per process) and a table built first, and is slower on long trials;
    ``tests/io/test_opensim_tables.py`` checks the bytes against OpenSim's
    adapter. The first line (``PathFileType 4 (X/Y/Z) <name>``) holds the
    bare file name, so the bytes do not depend on the directory. Reading
    takes the unit from the ``Units`` metadata (mm, cm or m) and refuses a
    file without it, since OpenSim itself would silently assume metres.
    Labels may hold inner spaces (``r heel``, as BTS exports them): the file
    is tab-separated, and OpenSim's adapter writes them as they are and reads
    them back unchanged (it strips only blanks at a label's ends, so labels
    with edge blanks, tabs or line breaks are refused, and the fast reader
    strips edge blanks as OpenSim does). OpenSim's model components, markers
    included, cannot carry a space in their name: such a label names a marker
    that no model has, until ``markers.label_map`` gives it a model name.

MOT/STO (:func:`write_mot`, :func:`read_mot`)
    Written with ``opensim.STOFileAdapter`` (header name line
    ``Coordinates``, ``inDegrees=yes|no``, ``DataType``, ``version=3``,
    ``OpenSimVersion``, ``endheader``; values to 16 significant digits).
    Columns whose name ends in ``_tx``, ``_ty`` or ``_tz`` are translations
    in m and never converted; every other column is an angle, rad inside,
    printed in degrees when ``inDegrees=yes``. The reader honours the
    header and refuses a file without ``inDegrees``.

External loads: :mod:`loper_analysis.io.external_loads`.

Vectors are handed to OpenSim as plain Python lists, never as
``opensim.StdVector*`` objects: those stop working in a process where ezc3d's
SWIG wrapper used its ``std::vector`` converters first (see
:func:`loper_analysis.io.c3d_writer.write_c3d`, Notes). Writers go through
the atomic writer (:func:`loper_analysis.io.atomic.staged`). Every problem raises
:class:`~loper_analysis.errors.LoperInputError` naming the file.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.checks import time_vector, uniform_step_s, unique_names
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import staged
from loper_analysis.io.c3d import LENGTH_UNITS_PER_M, read_c3d
from loper_analysis.io.osim import quiet_opensim
from loper_analysis.timing import timed_io

log = logging.getLogger(__name__)

__all__ = [
    "trc_data_rate_hz",
    "TRANSLATION_SUFFIXES",
    "read_markers",
    "read_mot",
    "write_mot",
    "write_trc",
]

#: Coordinate-name endings of translations (m), which are never converted to degrees.
TRANSLATION_SUFFIXES: tuple[str, ...] = ("_tx", "_ty", "_tz")


def _is_translation(name: str) -> bool:
    return name.endswith(TRANSLATION_SUFFIXES)


def _open_table(osim, path: Path, kind: str, what: str):
    """``osim.<kind>(path)`` with a missing file and OpenSim's exceptions turned into LoperInputError."""
    if not path.is_file():
        raise LoperInputError(f"{path}: {what} not found")
    try:
        return getattr(osim, kind)(str(path))
    except Exception as exc:  # OpenSim raises RuntimeError (and others) for unreadable files
        raise LoperInputError(f"{path}: OpenSim cannot read this {what}: {exc}") from exc


# ---------------------------------------------------------------- TRC


@timed_io
def write_trc(
    path: str | os.PathLike, time_s, markers_m, labels: Sequence[str], unit: str = "mm", rate_hz: float | None = None
) -> Path:
    """Write marker trajectories to a TRC file as OpenSim's ``TRCFileAdapter`` does, atomically; returns ``path``.

    Parameters
    ----------
    path : str or path-like
        Target ``.trc`` file (a missing directory is created).
    time_s : array_like
        Shape (n_frames,), s, strictly increasing and equally spaced (relative tolerance 1e-6); ``DataRate`` =
        1 / mean step. One frame (a snapshot static trial, which OpenSim's ScaleTool takes) needs ``rate_hz``.
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres; NaN (missing) is written as ``nan``.
    labels : sequence of str
        One unique marker name per marker: inner spaces allowed (``r heel``),
        no tabs, line breaks or blanks at either end.
    unit : {"mm", "cm", "m"}
        Unit of the file (``Units`` metadata); values are converted from m.
    rate_hz : float, optional
        The frame rate (Hz) of a one-frame file's ``DataRate``; with more frames their step gives it.

    Raises
    ------
    LoperInputError
        Bad shapes, labels, unit or times, infinite values, a missing
        directory or a failed write.
    """
    path = Path(path)
    source = str(path)
    if unit not in LENGTH_UNITS_PER_M:
        raise LoperInputError(f"{source}: unit must be one of {', '.join(LENGTH_UNITS_PER_M)}, got {unit!r}")
    t = time_vector(time_s, source, min_count=1 if rate_hz else 2, item="row")
    X = np.asarray(markers_m, dtype=float)
    labels = list(labels)
    if X.ndim != 3 or X.shape != (t.size, len(labels), 3) or not labels:
        raise LoperInputError(
            f"{source}: markers_m must have shape (n_frames = {t.size}, n_labels = {len(labels)} >= 1, 3), "
            f"got {X.shape}"
        )
    labels = unique_names(labels, "labels", source, allow_whitespace=False, allow_spaces=True)
    if np.any(np.isinf(X)):
        raise LoperInputError(
            f"{source}: markers_m holds infinite values (first at {tuple(np.argwhere(np.isinf(X))[0])})"
        )
    rate = f"{(1.0 / uniform_step_s(t, source) if t.size > 1 else float(rate_hz)):.12g}"
    values = (X * LENGTH_UNITS_PER_M[unit]).reshape(t.size, -1)
    n, m = t.size, len(labels)
    head = [
        f"PathFileType\t4\t(X/Y/Z)\t{path.name}",
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames",
        f"{rate}\t{rate}\t{n}\t{m}\t{unit}\t{rate}\t0\t{n}",
        "Frame#\tTime\t" + "".join(f"{label}\t\t\t" for label in labels),
        "\t\t" + "".join(f"X{i}\tY{i}\tZ{i}\t" for i in range(1, m + 1)),
        "",
    ]
    row = "%d\t%.16g\t" + "%.16g\t" * (3 * m)  # OpenSim's own layout and precision
    body = [row % (k + 1, t[k], *values[k]) for k in range(n)]
    with staged(path, "TRC file") as tmp, tmp.open("w", encoding="utf-8", newline="\n") as fh:
        fh.write("\n".join(head) + "\n")
        fh.write("\n".join(body) + "\n")
    return path


def _read_trc_text(path: Path) -> tuple[np.ndarray, np.ndarray, list[str]] | None:
    """Fast reader for the TRC layout OpenSim's ``TRCFileAdapter`` writes; None if the file deviates from it.

    OpenSim's own parser needs 3.6 s for a 4-minute trial (30,720 frames, 36
    markers), this one 0.3 s; ``tests/io/test_opensim_tables.py`` checks that both return
    the same arrays. Anything unexpected (header keys, counts, a units field
    we do not know) returns None and the caller falls back to OpenSim.
    """
    try:
        with path.open("r", encoding="utf-8") as fh:
            head = [fh.readline().rstrip("\r\n") for _ in range(5)]
        if not head[0].startswith("PathFileType"):
            return None
        meta = dict(zip(head[1].split("\t"), head[2].split("\t")))
        unit = meta.get("Units", "").strip().lower()
        n_frames, n_markers = int(meta["NumFrames"]), int(meta["NumMarkers"])
        names = head[3].split("\t")
        if unit not in LENGTH_UNITS_PER_M or names[:2] != ["Frame#", "Time"]:
            return None
        labels = [n.strip() for n in names[2:] if n.strip()]  # OpenSim strips a label's edge blanks too
        if len(labels) != n_markers:
            return None
        data = pd.read_csv(
            path,
            sep="\t",
            skiprows=5,
            header=None,
            skip_blank_lines=True,
            usecols=range(2 + 3 * n_markers),
            dtype=float,
            na_values=["nan", "NaN"],
            float_precision="round_trip",
        ).to_numpy()
    except (OSError, ValueError, KeyError, UnicodeDecodeError, pd.errors.ParserError, pd.errors.EmptyDataError):
        return None
    if data.shape != (n_frames, 2 + 3 * n_markers):
        return None
    X = data[:, 2:].reshape(n_frames, n_markers, 3) / LENGTH_UNITS_PER_M[unit]
    return _nominal_times(data[:, 1].copy(), meta.get("DataRate"), path), X, labels


#: Printed times within this share of a frame step of the header rate's grid are read on that grid.
_TIME_JITTER_FRACTION = 0.25


def _nominal_times(t: np.ndarray, rate, path: Path) -> np.ndarray:
    """A TRC's times on the grid of its header's ``DataRate`` when the printed times only round it.

    OpenSim's own files print times to a few digits (the gait2392 tutorial's 60 Hz static trial: 0.000,
    0.017, 0.033, ...), so their steps jitter by up to half the last digit. Where every printed time lies
    within :data:`_TIME_JITTER_FRACTION` of a step from ``t[0] + k / DataRate``, the grid's times are
    returned and the jitter is logged; otherwise (no rate, frames missing, another rate) the printed times.
    """
    try:
        rate_hz = float(rate)
    except (TypeError, ValueError):
        return t
    if not np.isfinite(rate_hz) or rate_hz <= 0 or t.size < 2 or not np.all(np.isfinite(t)):
        return t
    grid = t[0] + np.arange(t.size) / rate_hz
    jitter = float(np.max(np.abs(t - grid)))
    if jitter == 0.0 or jitter > _TIME_JITTER_FRACTION / rate_hz:
        return t
    log.info(
        "%s: times printed to a few digits (up to %.3g ms off the %g Hz grid of DataRate): read on that grid",
        path,
        1e3 * jitter,
        rate_hz,
    )
    return grid


def trc_data_rate_hz(path: str | os.PathLike) -> float | None:
    """The ``DataRate`` of a TRC file's header (Hz); None when the header does not give one."""
    try:
        with Path(path).open("r", encoding="utf-8") as fh:
            head = [fh.readline().rstrip("\r\n") for _ in range(3)]
        rate = float(dict(zip(head[1].split("\t"), head[2].split("\t")))["DataRate"])
    except (OSError, UnicodeDecodeError, KeyError, ValueError, IndexError):
        return None
    return rate if np.isfinite(rate) and rate > 0 else None


def _read_trc(path: Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    if path.is_file():
        fast = _read_trc_text(path)
        if fast is not None:
            return fast
    osim = quiet_opensim()
    table = _open_table(osim, path, "TimeSeriesTableVec3", "TRC file")
    if not table.hasTableMetaDataKey("Units"):
        raise LoperInputError(f"{path}: the TRC header does not declare Units; cannot tell mm from m")
    unit = table.getTableMetaDataAsString("Units").strip()
    if unit.lower() not in LENGTH_UNITS_PER_M:
        raise LoperInputError(f"{path}: unknown TRC Units '{unit}'; expected one of {', '.join(LENGTH_UNITS_PER_M)}")
    labels = list(table.getColumnLabels())
    rate = table.getTableMetaDataAsString("DataRate") if table.hasTableMetaDataKey("DataRate") else None
    t = _nominal_times(np.array(table.getIndependentColumn(), dtype=float), rate, path)
    if not labels:
        return t, np.zeros((t.size, 0, 3)), labels
    flat_table = table.flatten(["_x", "_y", "_z"])  # keep temporaries alive
    matrix = flat_table.getMatrix()
    flat = np.array(matrix.to_numpy(), dtype=float, copy=True)
    return t, flat.reshape(t.size, len(labels), 3) / LENGTH_UNITS_PER_M[unit.lower()], labels


@timed_io
def read_markers(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Marker trajectories in metres from a ``.trc`` (OpenSim) or ``.c3d`` (ezc3d) file.

    Parameters
    ----------
    path : str or path-like
        ``.trc`` or ``.c3d`` file (suffix case-insensitive).

    Returns
    -------
    time_s : numpy.ndarray
        Shape (n_frames,), s (the TRC's Time column; for a C3D
        ``(first_frame + k) / point_rate``).
    markers_m : numpy.ndarray
        Shape (n_frames, n_markers, 3), m, NaN where missing.
    labels : list of str
        Marker names, in file order.

    Raises
    ------
    LoperInputError
        Unknown suffix, missing or unreadable file, units not declared or
        unknown (see also :func:`~loper_analysis.io.c3d.read_c3d`).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".trc":
        return _read_trc(path)
    if suffix == ".c3d":
        rec = read_c3d(path)
        return rec.time_s, rec.markers_m, list(rec.marker_labels)
    raise LoperInputError(f"{path}: unknown marker file type '{path.suffix}'; expected .trc or .c3d")


# ---------------------------------------------------------------- MOT / STO


def _check_mot_suffix(path: Path) -> None:
    if path.suffix.lower() not in (".mot", ".sto"):
        raise LoperInputError(f"{path}: expected a .mot or .sto file, got suffix '{path.suffix}'")


def write_mot(path: str | os.PathLike, frame: pd.DataFrame, in_degrees: bool = True) -> Path:
    """Write coordinates to an OpenSim ``.mot``/``.sto`` file with ``STOFileAdapter``, atomically; returns ``path``.

    Parameters
    ----------
    path : str or path-like
        Target ``.mot`` or ``.sto`` file (a missing directory is created).
    frame : pandas.DataFrame
        Column ``time_s`` (s, finite, strictly increasing, >= 1 row) plus at
        least one coordinate column: rad, or m for names ending in ``_tx``,
        ``_ty``, ``_tz``. Names without whitespace; NaN is written as ``nan``.
    in_degrees : bool
        Print angles in degrees and declare ``inDegrees=yes`` (OpenSim's
        usual .mot); otherwise rad and ``inDegrees=no``.

    Raises
    ------
    LoperInputError
        Wrong suffix, no ``time_s`` or no coordinate column, bad names,
        non-numeric or infinite values, bad times, a failed write.
    """
    path = Path(path)
    t, names, values = storage_columns(path, frame, "coordinate columns")
    for j, name in enumerate(names):
        if in_degrees and not _is_translation(name):
            values[:, j] = np.degrees(values[:, j])
    return write_storage(path, t, values, names, "Coordinates", in_degrees, "motion file")


def storage_columns(path: Path, frame: pd.DataFrame, what: str) -> tuple[np.ndarray, list[str], np.ndarray]:
    """Checked times (n,), column names and values (n, m) of a table for a ``.mot``/``.sto`` file.

    ``frame`` has ``time_s`` (s, finite, strictly increasing, >= 1 row) and at
    least one numeric, finite-or-NaN column (``what`` names them in messages).

    Raises
    ------
    LoperInputError
        Wrong suffix, no ``time_s`` or no other column, bad names, non-numeric
        or infinite values, bad times; the message names ``path``.
    """
    source = str(path)
    _check_mot_suffix(path)
    if not isinstance(frame, pd.DataFrame) or "time_s" not in frame.columns:
        raise LoperInputError(f"{source}: frame must be a DataFrame with a 'time_s' column")
    names = unique_names([c for c in frame.columns if c != "time_s"], what, source, allow_whitespace=False)
    if not names or "time" in names:
        raise LoperInputError(
            f"{source}: frame needs {what.split()[0]} column(s) besides time_s (and none named 'time')"
        )
    t = time_vector(frame["time_s"].to_numpy(dtype=float), source, min_count=1, item="row")
    values = np.empty((t.size, len(names)))
    for j, name in enumerate(names):
        if not pd.api.types.is_numeric_dtype(frame[name].dtype) or pd.api.types.is_bool_dtype(frame[name].dtype):
            raise LoperInputError(f"{source}: column '{name}' is not numeric ({frame[name].dtype})")
        col = frame[name].to_numpy(dtype=float)
        if np.any(np.isinf(col)):
            raise LoperInputError(
                f"{source}: column '{name}' is infinite at row {int(np.flatnonzero(np.isinf(col))[0])}"
            )
        values[:, j] = col
    return t, names, values


def write_storage(
    path: Path, time_s: np.ndarray, values: np.ndarray, names: list[str], header: str, in_degrees: bool, what: str
) -> Path:
    """Write checked columns (:func:`storage_columns`) with OpenSim's ``STOFileAdapter``, atomically.

    ``header`` is the file's name line (``Coordinates``, ``ExternalLoads``);
    ``inDegrees`` is declared as ``in_degrees`` (the values are written as
    given); ``what`` names the file in messages.
    """
    osim = quiet_opensim()
    table = osim.TimeSeriesTable(time_s.tolist(), osim.Matrix.createFromMat(values), names)
    table.addTableMetaDataString("header", header)
    table.addTableMetaDataString("inDegrees", "yes" if in_degrees else "no")
    with staged(path, what) as tmp:
        try:
            osim.STOFileAdapter().write(table, str(tmp))
        except Exception as exc:
            raise LoperInputError(f"{path}: OpenSim could not write the {what}: {exc}") from exc
    return path


@timed_io
def read_mot(path: str | os.PathLike) -> pd.DataFrame:
    """Read an OpenSim ``.mot``/``.sto`` coordinate file (any OpenSim version) with angles in rad.

    Parameters
    ----------
    path : str or path-like
        ``.mot`` or ``.sto`` file with an ``inDegrees=yes|no`` header line.

    Returns
    -------
    pandas.DataFrame
        ``time_s`` (s) plus one float64 column per file column, in file
        order: rad (converted from degrees when ``inDegrees=yes``), or m for
        names ending in ``_tx``, ``_ty``, ``_tz``.

    Raises
    ------
    LoperInputError
        Wrong suffix, missing or unreadable file, ``inDegrees`` absent or
        not yes/no.
    """
    path = Path(path)
    _check_mot_suffix(path)
    osim = quiet_opensim()
    table = _open_table(osim, path, "TimeSeriesTable", "motion file")
    if not table.hasTableMetaDataKey("inDegrees"):
        raise LoperInputError(f"{path}: the header does not declare inDegrees; cannot tell degrees from radians")
    flag = table.getTableMetaDataAsString("inDegrees").strip().lower()
    if flag not in ("yes", "no"):
        raise LoperInputError(f"{path}: header inDegrees must be yes or no, got '{flag}'")
    names = list(table.getColumnLabels())
    t = np.array(table.getIndependentColumn(), dtype=float)
    matrix = table.getMatrix()
    values = np.array(matrix.to_numpy(), dtype=float, copy=True).reshape(t.size, len(names))
    out = {"time_s": t}
    for j, name in enumerate(names):
        col = values[:, j]
        out[name] = np.radians(col) if flag == "yes" and not _is_translation(name) else col
    return pd.DataFrame(out)
