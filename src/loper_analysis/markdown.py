"""Markdown rendering of the result tables (TSV for machines, Markdown for people)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = ["markdown_table", "write_markdown"]


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


def write_markdown(sections: Mapping[str, str | Path], out_md, title: str = "loper-analysis: result tables") -> None:
    """One Markdown file with a section per table: ``{heading: tsv_path}``; an empty TSV says so."""
    parts = [f"# {title}\n"]
    for heading, path in sections.items():
        text = Path(path).read_text()
        frame = pd.read_csv(path, sep="\t") if text.strip() else pd.DataFrame()
        body = markdown_table(frame) if len(frame.columns) else "(empty)\n"
        parts.append(f"## {heading}\n\n`{path}`\n\n{body}")
    out = Path(out_md)
    tmp = out.with_name(f".{out.name}.partial")
    tmp.write_text("\n".join(parts))
    tmp.replace(out)
