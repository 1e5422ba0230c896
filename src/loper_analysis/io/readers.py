"""Reading the pipeline's TSV tables, YAML documents and whole files (writing is :mod:`loper_analysis.io.atomic`)."""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.io.timing import timed_io

__all__ = ["read_bytes", "read_label_map", "read_label_maps", "read_tsv", "read_yaml"]


@timed_io
def read_tsv(path: str | os.PathLike, what: str = "table", columns: Sequence[str] = (), **read_csv) -> pd.DataFrame:
    """A TSV table; an empty file (zero bytes) gives an empty frame.

    ``columns`` must be present in a table that has rows; ``read_csv`` goes to
    :func:`pandas.read_csv`.

    Raises
    ------
    LoperInputError
        A missing or unreadable file, or a required column absent (naming the file and the column).
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"{path}: {what} not found")
    if path.stat().st_size == 0:
        return pd.DataFrame()
    try:
        table = pd.read_csv(path, sep="\t", **read_csv)
    except pd.errors.EmptyDataError:
        return pd.DataFrame()
    except (OSError, pd.errors.ParserError, UnicodeDecodeError, ValueError) as exc:
        raise LoperInputError(f"{path}: cannot read the {what} ({exc})") from None
    missing = [c for c in columns if c not in table.columns]
    if len(table) and missing:
        raise LoperInputError(f"{path}: {what}: column(s) {missing} missing (has {list(table.columns)})")
    return table


@timed_io
def read_bytes(path: str | os.PathLike, what: str = "file") -> bytes:
    """The whole content of a file (a figure to embed, say).

    Raises
    ------
    LoperInputError
        A missing or unreadable file (naming the file).
    """
    path = Path(path)
    try:
        return path.read_bytes()
    except OSError as exc:
        raise LoperInputError(f"{path}: cannot read the {what} ({exc.strerror or exc})") from None


@timed_io
def read_yaml(path: str | os.PathLike, what: str = "YAML file"):
    """The document of a YAML file.

    Raises
    ------
    LoperInputError
        A missing or unreadable file, or invalid YAML (naming the file).
    """
    path = Path(path)
    try:
        return yaml.safe_load(path.read_text())
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise LoperInputError(f"{path}: not a readable {what} ({exc})") from exc


@timed_io
def read_label_map(path: str | os.PathLike) -> dict[str, str]:
    """A marker label map {lab label: model marker} from a TSV or YAML file.

    ``.yaml``/``.yml``: one mapping ``label: marker``. Anything else is read
    as a TSV with the columns ``label`` and ``marker`` (further columns are
    ignored). Labels and markers are stripped of edge blanks.

    Raises
    ------
    LoperInputError
        A missing or unreadable file, a YAML document that is not a mapping
        of names to names, a TSV without the two columns, an empty cell, or
        a label given twice (naming the file and the value).
    """
    path = Path(path)
    if path.suffix.lower() in (".yaml", ".yml"):
        if not path.is_file():
            raise LoperInputError(f"{path}: label map not found")
        doc = read_yaml(path, "label map")
        if not isinstance(doc, dict):
            raise LoperInputError(
                f"{path}: a label map must be a YAML mapping 'label: marker', got {type(doc).__name__}"
            )
        pairs = list(doc.items())
    else:
        table = read_tsv(path, "label map", ("label", "marker"), dtype=str, keep_default_na=False)
        if table.empty:
            return {}
        pairs = list(zip(table["label"], table["marker"]))
    out: dict[str, str] = {}
    for row, (label, marker) in enumerate(pairs, start=1):
        if not isinstance(label, str) or not isinstance(marker, str) or not label.strip() or not marker.strip():
            raise LoperInputError(f"{path}: label map entry {row}: {label!r} -> {marker!r} is not a pair of names")
        if label.strip() in out:
            raise LoperInputError(f"{path}: label map names label '{label.strip()}' twice")
        out[label.strip()] = marker.strip()
    return out


def read_label_maps(label_map) -> dict[str, str] | None:
    """A label map given inline, read from its file (:func:`read_label_map`), or several such maps merged in order.

    ``label_map`` is a mapping {lab label: model marker}, a path, a sequence of mappings and paths (a later
    map's entry for a label wins: the map of every trial, then its kind's, then its own) or None (returned as
    None).
    """
    if label_map is None or isinstance(label_map, Mapping):
        return None if label_map is None else dict(label_map)
    if isinstance(label_map, (list, tuple)):
        merged: dict[str, str] = {}
        for part in label_map:
            merged.update(read_label_maps(part) or {})
        return merged
    return read_label_map(label_map)
