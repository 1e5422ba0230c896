"""The report's browser check (``benchmarks/report_screenshot.py``), loaded for the tests that open a report in
headless Chromium."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def report_screen():
    """The module ``benchmarks/report_screenshot.py`` (``chromium_path``, ``first_screen``, ``problems``)."""
    spec = importlib.util.spec_from_file_location("report_screenshot", ROOT / "benchmarks/report_screenshot.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module
