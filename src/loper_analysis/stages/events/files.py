"""The events stage's result files: name -> pattern under ``results/events/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "events": "{subject}/{trial}.events.tsv",
    "contacts": "{subject}/{trial}.contacts.tsv",
    "force": "{subject}/{trial}.force.tsv",
    "force_native": "{subject}/{trial}.force_native.tsv",
}
