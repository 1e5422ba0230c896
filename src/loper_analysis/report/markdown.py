"""Markdown rendering of the result tables (TSV for machines, Markdown for people)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

__all__ = ["markdown_table", "markdown_document"]


def _cell(value) -> str:
    if isinstance(value, (float, np.floating)):
        return "" if np.isnan(value) else f"{value:.4g}"
    return str(value).replace("|", "\\|")


def markdown_table(frame: pd.DataFrame) -> str:
    """A GitHub-flavoured Markdown table; floats with 4 significant digits, NaN empty."""
    header = "| " + " | ".join(map(str, frame.columns)) + " |"
    rule = "|" + "|".join("---" for _ in frame.columns) + "|"
    rows = ["| " + " | ".join(_cell(v) for v in row) + " |" for row in frame.itertuples(index=False)]
    return "\n".join([header, rule, *rows]) + "\n"


def markdown_document(
    sections: Sequence[tuple[str, str, pd.DataFrame]], title: str = "loper-analysis: result tables"
) -> str:
    """One Markdown document with a section per table: ``(heading, where the table lives, table)``.

    A table without columns is shown as ``(empty)``.
    """
    parts = [f"# {title}\n"]
    for heading, where, frame in sections:
        body = markdown_table(frame) if len(frame.columns) else "(empty)\n"
        parts.append(f"## {heading}\n\n`{where}`\n\n{body}")
    return "\n".join(parts)
