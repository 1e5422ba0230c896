"""The model stage's result files: name -> pattern under ``results/model/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "targets"]

FILES: dict[str, str] = {
    "generic": "{subject}/generic.osim",
    "scaled": "{subject}/scaled.osim",
    "scale": "{subject}/scale.tsv",
    "segments": "{subject}/segments.tsv",
}


def targets(study: Study) -> list[str]:
    """Every processed subject's segment table, and the scale report of those scaled here."""
    p, scaled, out = study.paths, set(study.scaled_subjects()), []
    for s in study.processed_subjects():
        out.append(fill(p.model.segments, subject=s))
        if s in scaled:
            out.append(fill(p.model.scale, subject=s))
    return out
