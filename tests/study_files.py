"""A study on a temporary raw folder, for the tests of the layout and of the study's checks."""

from __future__ import annotations

import copy
from pathlib import Path

import yaml

from loper_analysis.layout import Study
from loper_analysis.stages import STAGES, study_paths
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def study_on(tmp_path: Path, rows: dict, **config) -> Study:
    """The study of ``rows`` (subject -> sheet row) with the raw folder ``tmp_path/raw`` and the default config
    with the keys of ``config``'s sections replaced (``device={"subject": None}``); a C3D has plates unless it is
    ``walk-nodevice.c3d``; the notes said are kept in ``study.said``."""
    cfg = copy.deepcopy(CONFIG)
    for section, keys in config.items():
        cfg[section].update(keys)
    said: list[str] = []
    study = Study(
        rows,
        {name: stage_settings(cfg, name) for name in ("study", *(stage.name for stage in STAGES))},
        study_paths(str(tmp_path / "raw")),
        has_plates=lambda path: path.name != "walk-nodevice.c3d",
        note=said.append,
    )
    study.said = said
    return study


def touch(path: Path, data: bytes = b"x") -> Path:
    """Write ``data`` to ``path`` (its folders made); returns the path."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(data)
    return path


def device_config(**sections) -> dict:
    """The shipped config with the given sections of ``device`` (``leg``, ``tests``, ``analysis``, ...) replaced."""
    config = copy.deepcopy(CONFIG)
    config["device"].update(sections)
    return config
