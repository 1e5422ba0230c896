"""What every test module may use: the repository's root, a fresh copy of the workflow, a project folder as the
working directory, and the `slow` lane.

Tests marked ``slow`` run Snakemake or OpenSim on whole trials (end-to-end runs, recorded labs, the
guards that need a processed project). ``pytest -m "not slow"`` leaves them out for day-to-day work;
CI runs them all.
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from tests.workflow_copy import ROOT, copy_workflow


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Test files holding a ``slow`` test first, each file's own order kept: run one file to a process
    (``--dist loadfile``), the long end-to-end files start at once and the short ones fill in behind them,
    instead of the long ones starting last and running on alone."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)


#: Seed of the ``rng`` fixture where the test module sets no ``RNG_SEED`` of its own.
DEFAULT_RNG_SEED = 20240611


@pytest.fixture
def rng(request) -> np.random.Generator:
    """A fresh seeded generator for each test: the module's ``RNG_SEED``, else :data:`DEFAULT_RNG_SEED`."""
    return np.random.default_rng(getattr(request.module, "RNG_SEED", DEFAULT_RNG_SEED))


@pytest.fixture(scope="session")
def repo_root() -> Path:
    """The repository's root folder."""
    return ROOT


@pytest.fixture
def workflow_dir(tmp_path: Path) -> Path:
    """A fresh copy of the workflow files (Snakefile, rules, config, examples) in the test's own folder."""
    return copy_workflow(tmp_path)


@pytest.fixture
def project(tmp_path: Path, monkeypatch) -> Path:
    """A project folder as the working directory: ``config/config.yaml`` and the config schema, as in the
    repository (what ``loper-analysis`` reads when run where the workflow lives)."""
    (tmp_path / "config").mkdir()
    shutil.copy(ROOT / "config" / "config.yaml", tmp_path / "config" / "config.yaml")
    (tmp_path / "workflow" / "schemas").mkdir(parents=True)
    shutil.copy(ROOT / "workflow/schemas/config.schema.yaml", tmp_path / "workflow/schemas/config.schema.yaml")
    monkeypatch.chdir(tmp_path)
    return tmp_path


@pytest.fixture
def second(project: Path) -> Path:
    """A file layered over config/config.yaml: a wider fit window and other stride counts
    (:mod:`tests.config_layers`)."""
    from tests.config_layers import STRIDES, WINDOW_AFTER_S, write_yaml

    return write_yaml(
        project / "config" / "mine.yaml",
        {"identification": {"window_after_s": WINDOW_AFTER_S}, "planning": {"strides": STRIDES}},
    )
