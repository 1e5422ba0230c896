"""Reading the pipeline's TSV tables, YAML documents and whole files (writing is :mod:`loper_analysis.io.atomic`)."""

from __future__ import annotations

import io
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.timing import timed_io

__all__ = ["read_bytes", "read_label_map", "read_label_maps", "read_subject_sheet", "read_tsv", "read_yaml"]


#: Columns that hold names (a subject ``NA``, a trial ``null``): text, missing only when empty.
NAME_COLUMNS: tuple[str, ...] = ("subject", "trial")
#: What pandas reads as missing by default (its documented list), kept for every other column.
PANDAS_NA_VALUES: tuple[str, ...] = (
    "", "#N/A", "#N/A N/A", "#NA", "-1.#IND", "-1.#QNAN", "-NaN", "-nan", "1.#IND", "1.#QNAN", "<NA>", "N/A", "NA",
    "NULL", "NaN", "None", "n/a", "nan", "null",
)  # fmt: skip


def _name_columns_as_text(path: Path, read_csv: dict) -> dict:
    """``read_csv`` with the name columns of the file's header (:data:`NAME_COLUMNS`) read as text, missing only
    when empty; unchanged when the caller sets its own missing values or the file has no such column."""
    if "keep_default_na" in read_csv or "na_values" in read_csv:
        return read_csv
    with path.open(encoding="utf-8", errors="replace") as fh:
        header = fh.readline().rstrip("\r\n").split("\t")
    names = [c for c in header if c in NAME_COLUMNS]
    if not names:
        return read_csv
    na = {c: ([""] if c in names else list(PANDAS_NA_VALUES)) for c in header}
    dtype = read_csv.get("dtype")
    if dtype is None or isinstance(dtype, dict):
        dtype = {**dict.fromkeys(names, str), **(dtype or {})}
    return {**read_csv, "keep_default_na": False, "na_values": na, "dtype": dtype}


@timed_io
def read_tsv(path: str | os.PathLike, what: str = "table", columns: Sequence[str] = (), **read_csv) -> pd.DataFrame:
    """A TSV table; an empty file (zero bytes) gives an empty frame.

    ``columns`` must be present in a table that has rows; ``read_csv`` goes to
    :func:`pandas.read_csv`. The name columns (:data:`NAME_COLUMNS`) are text, missing only when empty (a
    subject named ``NA`` stays ``NA``), unless ``read_csv`` sets its own missing values.

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
        table = pd.read_csv(path, sep="\t", **_name_columns_as_text(path, read_csv))
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


#: Columns of a subject sheet read as numbers (a decimal comma in them is named).
SHEET_NUMBER_COLUMNS: tuple[str, ...] = ("age_yr", "height_m", "mass_kg")


def _sheet_text(path: Path) -> str:
    """A sheet's text as spreadsheets save it: UTF-16 with its byte-order mark ("Unicode text"), UTF-8 with or
    without one, else Latin-1; line ends of any system."""
    raw = read_bytes(path, "subject sheet")
    if raw.startswith((b"\xff\xfe", b"\xfe\xff")):
        text = raw.decode("utf-16")
    else:
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            text = raw.decode("latin-1")
    return text.replace("\r\n", "\n").replace("\r", "\n")


def read_subject_sheet(path: str | os.PathLike) -> pd.DataFrame:
    """The subject sheet (TSV, one row per subject), read as a spreadsheet saves it.

    Encodings: UTF-16 with a byte-order mark (a spreadsheet's "Unicode text"), UTF-8 with or without one, else
    Latin-1; Windows or old Mac line ends; lines starting with ``#`` and blank lines are skipped; empty cells at
    a row's end beyond the header's columns (trailing tabs) are dropped. ``subject`` is text (``NA`` a name, not a
    missing value; only an empty cell is missing in the text columns); ``age_yr``,
    ``height_m`` and ``mass_kg`` numbers (empty: NaN).

    Raises
    ------
    LoperInputError
        A missing or unreadable file, no header, a row with more filled cells than the header has columns, or a
        number that is none (a decimal comma ``1,75`` is named as such), each naming the sheet, the row (its
        line in the file) and the column.
    """
    path = Path(path)
    if not path.is_file():
        raise LoperInputError(f"{path}: subject sheet not found")
    lines = [(n, line) for n, line in enumerate(_sheet_text(path).split("\n"), start=1)]
    lines = [(n, line) for n, line in lines if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise LoperInputError(f"{path}: the subject sheet is empty (no header line)")
    header = [c.strip() for c in lines[0][1].split("\t")]
    while header and header[-1] == "":
        header.pop()
    kept = ["\t".join(header)]
    for n, line in lines[1:]:
        cells = [c.strip() for c in line.split("\t")]
        extra = cells[len(header) :]
        if any(extra):
            raise LoperInputError(
                f"{path}: line {n}: {len(cells)} cells for the header's {len(header)} columns "
                f"({', '.join(header)}); the extra ones hold {[c for c in extra if c]}"
            )
        cells = (cells + [""] * len(header))[: len(header)]
        for column, value in zip(header, cells):
            if column in SHEET_NUMBER_COLUMNS:
                _sheet_number(value, path, n, column)
        kept.append("\t".join(cells))
    text = ["subject", "source", "sex", "model_osim"]  # missing only when empty: a subject may be named NA
    na = {c: ([""] if c in text else list(PANDAS_NA_VALUES)) for c in header}
    return pd.read_csv(
        io.StringIO("\n".join(kept) + "\n"), sep="\t", dtype={"subject": str}, keep_default_na=False, na_values=na
    )


def _sheet_number(text: str, path: Path, line: int, column: str) -> float:
    if text == "":
        return float("nan")
    try:
        return float(text)
    except ValueError:
        if "," in text and text.replace(",", ".", 1).replace(".", "", 1).isdigit():
            raise LoperInputError(
                f"{path}: line {line}, column '{column}': '{text}' has a decimal comma; write {text.replace(',', '.')}"
            ) from None
        raise LoperInputError(f"{path}: line {line}, column '{column}': '{text}' is not a number") from None
