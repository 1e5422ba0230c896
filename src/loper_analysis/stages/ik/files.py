"""The ik stage's result files: name -> pattern under ``results/ik/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "mot": "{subject}/{trial}.mot",
    "chunk": "{subject}/{trial}.chunk{chunk}.mot",
    "angles": "{subject}/{trial}.angles.tsv",
    "summary": "{subject}/{trial}.ik.tsv",
    "agreement": "{subject}/{trial}.lab_agreement.tsv",
}
