"""File step of the result tables in Markdown (``results/tables/tables.md``)."""

from __future__ import annotations

import logging
from collections.abc import Sequence

from ..io.atomic import PathLike, write_text
from ..io.readers import read_tsv

__all__ = ["markdown_tables"]

log = logging.getLogger(__name__)


def markdown_tables(headings: Sequence[str], tsvs: Sequence[PathLike], out_md: PathLike) -> str:
    """Render every table (one TSV per heading, in order) into one Markdown file; an empty TSV says so."""
    from ..markdown import markdown_document

    sections = [(heading, str(path), read_tsv(path, "table")) for heading, path in zip(headings, tsvs, strict=True)]
    text = markdown_document(sections)
    write_text(out_md, text, "Markdown file")
    log.info("rendered %d tables", len(sections))
    return text
