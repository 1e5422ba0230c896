"""File step of the result tables in Markdown (``results/tables/tables.md``)."""

from __future__ import annotations

import logging
from collections.abc import Mapping

from ..io.atomic import PathLike, write_text
from ..io.readers import read_tsv

__all__ = ["markdown_tables"]

log = logging.getLogger(__name__)


def markdown_tables(sections: Mapping[str, PathLike], out_md: PathLike) -> str:
    """Render every table of ``{heading: tsv_path}`` into one Markdown file; an empty TSV says so."""
    from ..markdown import markdown_document

    text = markdown_document([(heading, str(path), read_tsv(path, "table")) for heading, path in sections.items()])
    write_text(out_md, text, "Markdown file")
    log.info("rendered %d tables", len(sections))
    return text
