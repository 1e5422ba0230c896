"""The report stage's result files: name -> pattern under ``results/report/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "tables": "tables.md",
    "front_page": "front_page.html",
}
