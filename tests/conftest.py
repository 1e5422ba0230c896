"""What every test module may use: the repository's root, a fresh copy of the workflow, and the `slow` lane.

Tests marked ``slow`` run Snakemake or OpenSim on whole trials (end-to-end runs, recorded labs, the
guards that need a processed project). ``pytest -m "not slow"`` leaves them out for day-to-day work;
CI runs them all.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.workflow_copy import ROOT, copy_workflow


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository's root folder."""
    return ROOT


@pytest.fixture
def workflow_dir(tmp_path: Path) -> Path:
    """A fresh copy of the workflow files (Snakefile, rules, config, examples) in the test's own folder."""
    return copy_workflow(tmp_path)
