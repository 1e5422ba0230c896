"""A config file layered over config/config.yaml, for the tests of the config reader and the commands that
read it: the values of the ``second`` fixture (``tests/conftest.py``), which differ from the library's defaults."""

from __future__ import annotations

from pathlib import Path

import yaml

#: Values that differ from the library's defaults (PlanSettings, PlanningSettings).
WINDOW_AFTER_S = 0.3
STRIDES = [7, 14]


def write_yaml(path: Path, data: dict) -> Path:
    """``data`` written as YAML to ``path``; returns the path."""
    path.write_text(yaml.safe_dump(data))
    return path
