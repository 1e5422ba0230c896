"""The model stage's result files: name -> pattern under ``results/model/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "generic": "{subject}/generic.osim",
    "scaled": "{subject}/scaled.osim",
    "scale": "{subject}/scale.tsv",
    "segments": "{subject}/segments.tsv",
}
