"""The transparency stage's result files: name -> pattern under ``results/transparency/`` (wildcards in braces)."""

from __future__ import annotations

__all__ = ["FILES"]

FILES: dict[str, str] = {
    "rmsd": "rmsd.tsv",
    "force": "force.tsv",
    "figure": "transparency.png",
}
