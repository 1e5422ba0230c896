"""The device stage's result files: name -> pattern under ``results/device/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "targets"]

FILES: dict[str, str] = {
    "robot_log": "{subject}/{trial}.loper.tsv",
    "frf": "frf.tsv",
    "step_metrics": "step_metrics.tsv",
    "step_average": "step_average.tsv",
    "summary": "summary.tsv",
    "bode": "bode.png",
    "steps": "steps.png",
}


def targets(study: Study) -> list[str]:
    """The device tests' summary and figures, with a device subject (``device.subject`` not null)."""
    d = study.paths.device
    return [d.summary, d.bode, d.steps] if study.has_device_tests() else []
