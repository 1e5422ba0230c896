"""A fresh copy of the repository's workflow files, and Snakemake run in it, for the end-to-end tests."""

from __future__ import annotations

import shutil
import subprocess
import sys
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


def snakemake(work: Path, *args: str, timeout: float = 900) -> subprocess.CompletedProcess:
    """``snakemake --cores 2 ARGS`` of this Python in ``work``; its output captured as text, never raising."""
    return subprocess.run(
        [sys.executable, "-m", "snakemake", "--cores", "2", *args],
        cwd=work,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
