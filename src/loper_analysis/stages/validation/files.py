"""The validation stage's result files: name -> pattern under ``results/validation/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "report_tables", "targets"]

FILES: dict[str, str] = {
    "segments": "segments.tsv",
    "chunk_errors": "chunks/{chunk}.errors.tsv",
    "chunk_fits": "chunks/{chunk}.fits.tsv",
    "errors": "errors.tsv",
    "fits": "fits.tsv",
    "summary": "summary.tsv",
    "figure": "errors.png",
}


def targets(study: Study) -> list[str]:
    """The validation study's tables and figure: for a study with perturbation trials, or without subjects."""
    v = study.paths.validation
    return [v.summary, v.errors, v.fits, v.figure] if study.has_validation() else []


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: the validation study's summary."""
    return {"Validation study": study.paths.validation.summary}
