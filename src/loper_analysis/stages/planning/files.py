"""The planning stage's result files: name -> pattern under ``results/planning/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "plan": "plan.tsv",
    "answers": "answers.txt",
}
