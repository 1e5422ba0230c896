"""The impedance stage's result files: name -> pattern under ``results/impedance/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "response": "{subject}/{onset}.response.tsv",
    "counts": "{subject}/{onset}.counts.tsv",
    "fit": "{subject}/{onset}.tsv",
    "curves": "{subject}/{onset}.curves.tsv",
    "force": "{subject}/{onset}.force.tsv",
    "responses_figure": "{subject}/responses.png",
    "fit_figure": "{subject}/fit.png",
    "table": "impedance.tsv",
    "summary": "summary.tsv",
    "literature": "literature.tsv",
    "figure": "impedance.png",
}
