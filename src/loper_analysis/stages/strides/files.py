"""The strides stage's result files: name -> pattern under ``results/strides/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "strides": "{subject}/{trial}.strides.tsv",
    "cycles": "{subject}/{trial}.cycles.tsv",
    "dropped": "{subject}/{trial}.dropped.tsv",
    "figure": "{subject}/{trial}.angles.png",
    "summary": "summary.tsv",
}
