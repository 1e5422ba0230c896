"""The synthetic stage's result files: name -> pattern under ``results/synthetic/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "targets"]

FILES: dict[str, str] = {}


def targets(study: Study) -> list[str]:
    """The truth of every processed synthetic subject (its raw files follow from the stages that read them)."""
    rows = [s for s in study.processed_subjects() if study.source(s) == "synthetic"]
    return [fill(study.paths.raw.truth, subject=s) for s in rows]
