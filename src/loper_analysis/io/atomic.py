"""The one atomic writer: every output of the pipeline is staged beside its target and moved over it whole.

:func:`staged` yields a temporary path with the target's own file name, in
a fresh hidden directory beside the target (so writers that look at the
suffix or print the name, like OpenSim's adapters, see the real one). When
the body returns, the file is moved over the target with :func:`os.replace`
(atomic on one file system); when the body raises, or the move fails, the
staging directory is removed and the target is left as it was. A reader
therefore sees either the old file or the complete new one, never a part.

The other functions are the writers of the common kinds of output (bytes,
text, tidy TSV, figures, YAML), all through :func:`staged`. Writers of file
formats with their own libraries (C3D, TRC/.mot, .osim) call :func:`staged`
themselves.
"""

from __future__ import annotations

import contextlib
import glob
import os
import shutil
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.timing import io_clock

__all__ = [
    "PathLike",
    "TSV_FLOAT_FORMAT",
    "FIGURE_DPI",
    "stage_name",
    "staged",
    "write_bytes",
    "write_text",
    "write_tsv",
    "write_figure",
    "write_yaml",
]

#: A file path as the writers and steps take it.
PathLike = str | os.PathLike
#: Default float format of tidy TSV tables (9 significant digits: below any measurement's precision).
TSV_FLOAT_FORMAT = "%.9g"
#: Resolution of PNG figures.
FIGURE_DPI = 110
#: Random characters in a staging directory's name (those of :func:`tempfile.mkdtemp`).
_STAGE_RANDOM_CHARS = 8
#: Column types :func:`write_tsv` formats itself; characters that make pandas quote a column name.
_NUMERIC_COLUMNS = (np.dtype(np.float64), np.dtype(np.int64))
_QUOTED_CHARACTERS = frozenset('\t"\n\r')


def stage_name(name: str) -> str:
    """The name of the staging directory of a file named ``name`` (its random characters shown as ``X``):
    ``.{name}.XXXXXXXX.partial``, the longest name the writers create for that file."""
    return f".{name}.{'X' * _STAGE_RANDOM_CHARS}.partial"


def _remove_stale_stages(path: Path) -> None:
    """Remove staging directories of ``path`` left by a writer that was killed (one writer per target)."""
    for stale in path.parent.glob(f".{glob.escape(path.name)}.{'?' * _STAGE_RANDOM_CHARS}.partial"):
        if stale.is_dir() and not stale.is_symlink():
            shutil.rmtree(stale, ignore_errors=True)


@contextlib.contextmanager
def staged(path: str | os.PathLike, what: str = "file") -> Iterator[Path]:
    """Yield a temporary path for ``path``; on success move it over ``path``, on failure leave nothing.

    The parent directory is created when missing. ``what`` names the kind of
    file in error messages. Staging directories of the same target left by a
    writer that was killed (SIGKILL, power loss) are removed first: a target
    has one writer at a time, so they can only be stale. The body's wall
    time counts as file I/O (:mod:`loper_analysis.timing`).

    Raises
    ------
    LoperInputError
        The directory cannot be created or written, or the finished file
        cannot be moved into place (the message names the path and the cause).
    """
    with io_clock():
        with _staged(path, what) as tmp:
            yield tmp


@contextlib.contextmanager
def _staged(path: str | os.PathLike, what: str) -> Iterator[Path]:
    path = Path(path)
    directory = path.parent
    try:
        directory.mkdir(parents=True, exist_ok=True)
        _remove_stale_stages(path)
        stage = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".partial", dir=directory))
    except OSError as exc:
        raise LoperInputError(f"{path}: cannot write {what} ({exc})") from exc
    try:
        tmp = stage / path.name
        yield tmp
        if not tmp.is_file():
            raise LoperInputError(f"{path}: cannot write {what}: the writer produced no file")
        try:
            os.replace(tmp, path)
        except OSError as exc:
            raise LoperInputError(f"{path}: cannot write {what} ({exc})") from exc
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def write_bytes(path: str | os.PathLike, data: bytes, what: str = "file") -> Path:
    """Write ``data`` to ``path`` atomically; returns the path."""
    with staged(path, what) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_text(path: str | os.PathLike, text: str, what: str = "file") -> Path:
    """Write UTF-8 ``text`` to ``path`` atomically; returns the path."""
    return write_bytes(path, text.encode("utf-8"), what)


def write_tsv(frame: pd.DataFrame, path: str | os.PathLike, float_format: str = TSV_FLOAT_FORMAT) -> Path:
    """Write a tidy table as TSV atomically: no index, ``\\n`` line ends, NaN empty, floats by ``float_format``.

    The same frame gives the same bytes: those of pandas' ``to_csv`` with these options.
    """
    text = _numeric_table_text(frame, float_format)
    if text is not None:
        return write_text(path, text, "table")
    with staged(path, "table") as tmp:
        frame.to_csv(tmp, sep="\t", index=False, float_format=float_format, na_rep="", lineterminator="\n")
    return Path(path)


def _numeric_table_text(frame: pd.DataFrame, float_format: str) -> str | None:
    """The TSV text of a table of float64 and int64 columns (two or more, plain names), or None for another.

    The text is byte for byte what pandas' ``to_csv`` writes, which formats each value in Python behind a
    missing-value check of its own; formatting the columns' Python floats and joining the lines here is about
    four times faster on the long tables (a 4-minute trial's force at 1 kHz, its IK at 128 Hz).
    """
    if frame.shape[1] < 2 or isinstance(frame.columns, pd.MultiIndex):
        return None  # pandas quotes a lone empty value
    names = [str(c) for c in frame.columns]
    if not all(name and not set(name) & _QUOTED_CHARACTERS for name in names):
        return None  # pandas quotes these names
    if any(dtype not in _NUMERIC_COLUMNS for dtype in frame.dtypes):
        return None
    columns = []
    for k, dtype in enumerate(frame.dtypes):
        values = frame.iloc[:, k].tolist()
        if dtype == np.float64:
            columns.append(["" if v != v else float_format % v for v in values])
        else:
            columns.append([str(v) for v in values])
    lines = ["\t".join(names), *map("\t".join, zip(*columns))]
    return "\n".join(lines) + "\n"


def write_figure(figure, path: str | os.PathLike, dpi: int = FIGURE_DPI, close: bool = True) -> Path:
    """Render a matplotlib figure to PNG atomically (no software tag: the same figure gives the same bytes).

    The figure is closed afterwards (also when rendering fails) unless ``close`` is False.
    """
    try:
        with staged(path, "figure") as tmp:
            figure.savefig(tmp, format="png", dpi=dpi, metadata={"Software": None})
    finally:
        if close:
            import matplotlib.pyplot as plt

            plt.close(figure)
    return Path(path)


def write_yaml(path: str | os.PathLike, document, header: str = "") -> Path:
    """Write a YAML document (keys in the given order) atomically, after an optional ``# header`` line."""
    text = (f"# {header}\n" if header else "") + yaml.safe_dump(document, sort_keys=False)
    return write_text(path, text, "YAML file")
