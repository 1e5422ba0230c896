"""The parameter-section reader against ezc3d on files others wrote and on the example lab's files."""

from __future__ import annotations

from pathlib import Path

import ezc3d
import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_parameter_section import force_platforms_used, read_parameter

ROOT = Path(__file__).resolve().parents[2]
FILES = [ROOT / "tests/data/opensim-core/walking5.c3d", *sorted((ROOT / "examples/rajagopal2016/raw").rglob("*.c3d"))]
PARAMETERS = [
    ("FORCE_PLATFORM", "USED"),
    ("FORCE_PLATFORM", "CORNERS"),
    ("FORCE_PLATFORM", "ORIGIN"),
    ("FORCE_PLATFORM", "CHANNEL"),
    ("POINT", "RATE"),
    ("POINT", "SCALE"),
    ("ANALOG", "GEN_SCALE"),
]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_numbers_equal_ezc3d(path):
    params = ezc3d.c3d(str(path))["parameters"]
    for group, name in PARAMETERS:
        theirs = np.asarray(params[group][name]["value"], dtype=float)
        mine = read_parameter(path, group, name)
        assert mine.shape == theirs.shape and np.array_equal(mine, theirs), (group, name)


def test_text_and_absent_parameters(tmp_path):
    path = FILES[0]
    assert read_parameter(path, "POINT", "UNITS") == "mm"
    assert read_parameter(path, "point", "units") == "mm"  # names are case-blind, as in C3D
    assert read_parameter(path, "FORCE_PLATFORM", "NO_SUCH") is None
    assert read_parameter(path, "NO_GROUP", "USED") is None
    assert read_parameter(path, "FORCE_PLATFORM", "USED").tolist() == [2] and force_platforms_used(path) == 2
    (tmp_path / "short.c3d").write_bytes(path.read_bytes()[:300])
    with pytest.raises(LoperInputError, match=r"short.c3d: not a C3D file: 300 bytes, shorter than its header"):
        read_parameter(tmp_path / "short.c3d", "FORCE_PLATFORM", "USED")
