"""Reading the pipeline's tidy TSV tables and YAML documents (writing is :mod:`loper_analysis.io.atomic`)."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import pandas as pd
import yaml

from ..errors import LoperInputError

__all__ = ["read_tsv", "read_yaml"]


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
