"""The strides stage's result files: name -> pattern under ``results/strides/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "report_tables", "targets"]

FILES: dict[str, str] = {
    "strides": "{subject}/{trial}.strides.tsv",
    "cycles": "{subject}/{trial}.cycles.tsv",
    "dropped": "{subject}/{trial}.dropped.tsv",
    "figure": "{subject}/{trial}.angles.png",
    "summary": "summary.tsv",
}


def targets(study: Study) -> list[str]:
    """Every processed trial's stride table, a recorded subject's joint-angle figure of each walking trial, and
    the stride summary."""
    p, out = study.paths, []
    for s in study.processed_subjects():
        out += [fill(p.strides.strides, subject=s, trial=t) for t in study.subject_trials(s)]
        if study.source(s) == "recorded":
            out += [fill(p.strides.figure, subject=s, trial=t) for t in study.subject_trials(s)]
    return [*out, p.strides.summary] if study.processed_subjects() else out


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: the strides per trial."""
    return {"Strides per trial": study.paths.strides.summary}
