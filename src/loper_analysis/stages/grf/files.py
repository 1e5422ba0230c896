"""The grf stage's result files: name -> pattern under ``results/grf/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "targets"]

FILES: dict[str, str] = {
    "mot": "{subject}/{trial}.grf.mot",
    "figure": "{subject}/{trial}.grf.png",
}


def targets(study: Study) -> list[str]:
    """A recorded subject's force platforms as OpenSim external loads, and their figure, for every walking trial
    with force platforms."""
    p, out = study.paths, []
    for s in study.processed_subjects():
        if study.source(s) == "recorded":
            plated = [t for t in study.subject_trials(s) if study.has_force_platforms(s, t)]
            out += [fill(p.grf.mot, subject=s, trial=t) for t in plated]
            out += [fill(p.grf.figure, subject=s, trial=t) for t in plated]
    return out
