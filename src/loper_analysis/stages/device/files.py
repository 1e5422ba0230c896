"""The device stage's result files: name -> pattern under ``results/device/`` (wildcards in braces)."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "report_tables", "targets"]

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


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: the device tests' summary, with a device subject."""
    if not study.has_device_tests():  # no device tests without a device subject (device.subject null)
        return {}
    return {"Device": study.paths.device.summary}
