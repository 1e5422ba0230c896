"""The synthetic stage's result files: name -> pattern under ``results/synthetic/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {}
