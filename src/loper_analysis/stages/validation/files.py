"""The validation stage's result files: name -> pattern under ``results/validation/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "segments": "segments.tsv",
    "chunk_errors": "chunks/{chunk}.errors.tsv",
    "chunk_fits": "chunks/{chunk}.fits.tsv",
    "errors": "errors.tsv",
    "fits": "fits.tsv",
    "summary": "summary.tsv",
    "figure": "errors.png",
}
