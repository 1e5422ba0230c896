"""The device stage's result files: name -> pattern under ``results/device/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "robot_log": "{subject}/{trial}.loper.tsv",
    "frf": "frf.tsv",
    "step_metrics": "step_metrics.tsv",
    "step_average": "step_average.tsv",
    "summary": "summary.tsv",
    "bode": "bode.png",
    "steps": "steps.png",
}
