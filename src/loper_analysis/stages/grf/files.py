"""The grf stage's result files: name -> pattern under ``results/grf/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "mot": "{subject}/{trial}.grf.mot",
    "figure": "{subject}/{trial}.grf.png",
}
