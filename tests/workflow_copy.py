"""A fresh copy of the repository's workflow files, for tests that run Snakemake in a folder of their own."""

from __future__ import annotations

import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: What a run needs from the repository: the Snakefile, the rules and scripts, the config and the examples.
WORKFLOW_ITEMS = ("Snakefile", "workflow", "config", "examples")


def copy_workflow(work: Path) -> Path:
    """Copy :data:`WORKFLOW_ITEMS` into ``work``; returns ``work``."""
    for item in WORKFLOW_ITEMS:
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
    return work
