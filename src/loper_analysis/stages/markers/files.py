"""The markers stage's result files: name -> pattern under ``results/markers/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "trc": "{subject}/{trial}.trc",
    "gaps": "{subject}/{trial}.gaps.tsv",
    "summary": "{subject}/{trial}.markers.tsv",
    "lab_angles": "{subject}/{trial}.lab_angles.tsv",
}
