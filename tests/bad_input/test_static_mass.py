"""The mass from the static trial's force plates only when the subject stands on them with both feet.

A clinical lab's Plug-in Gait static trial (both feet on plate 3; its ``PROCESSING:Bodymass`` 70.23 kg) read
as recorded, and written again with the left foot beside the plates: its markers 0.6 m to the side and plate
3 carrying half the weight, as a subject standing with one foot on the floor gives it.
"""

from __future__ import annotations

import logging
import subprocess
import sys
from pathlib import Path

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import read_model
from loper_analysis.stages.model.step import ModelSettings, generic_model

STATIC = Path(__file__).resolve().parents[1] / "data/c3d-parser/QCMAS/static.c3d"


#: Run in a child process: ezc3d and OpenSim in one process break each other's vector arguments.
FOOT_BESIDE = """
import sys

import ezc3d
import numpy as np

src, out, bodymass = sys.argv[1], sys.argv[2], float(sys.argv[3])
c = ezc3d.c3d(src)
labels = list(c["parameters"]["POINT"]["LABELS"]["value"])
points = c["data"]["points"]
for name in ("LANK", "LHEE", "LTOE", "LMMAL"):
    points[0, labels.index(name), :] += 600.0  # mm, beyond the plates' far edge (x 0 .. 0.46 m)
analogs = c["data"]["analogs"]
analogs[0, 12:18, :] *= 0.5  # plate 3: FORCE_PLATFORM:CHANNEL 13..18 (offsets 0, scales 1)
c["data"]["points"] = points
c["data"]["analogs"] = analogs
c["parameters"]["PROCESSING"]["Bodymass"]["value"] = np.array([bodymass])
c.write(out)
"""


def _one_foot_beside(out: Path, bodymass_kg: float) -> Path:
    subprocess.run([sys.executable, "-c", FOOT_BESIDE, str(STATIC), str(out), str(bodymass_kg)], check=True)
    return out


def _model_mass_kg(path: Path) -> float:
    model = read_model(path)
    bodies = model.getBodySet()
    return sum(bodies.get(i).getMass() for i in range(bodies.getSize()))


def test_both_feet_on_a_loaded_plate_give_the_mass_from_the_plates(tmp_path, caplog):
    caplog.set_level(logging.INFO)
    generic_model(tmp_path / "m.osim", 1.86, None, STATIC, ModelSettings())
    assert _model_mass_kg(tmp_path / "m.osim") == pytest.approx(72.23, abs=0.05)  # 708.4 N / g
    assert "from the force plate 3 of static.c3d (1, 2, 4 unloaded)" in caplog.text


def test_one_foot_beside_the_plates_takes_the_files_bodymass_and_says_why(tmp_path, caplog):
    caplog.set_level(logging.INFO)
    c3d = _one_foot_beside(tmp_path / "static.c3d", 70.23)
    generic_model(tmp_path / "m.osim", 1.86, None, c3d, ModelSettings())
    assert _model_mass_kg(tmp_path / "m.osim") == pytest.approx(70.23, abs=1e-3)  # not 36 kg from the plates
    said = caplog.text
    assert "PROCESSING:Bodymass of static.c3d" in said
    assert "foot markers LANK, LHEE, LTOE, LMMAL" in said and "beside the loaded plates (3)" in said


def test_one_foot_beside_the_plates_without_a_bodymass_stops_naming_the_markers(tmp_path):
    c3d = _one_foot_beside(tmp_path / "static.c3d", 0.0)
    with pytest.raises(LoperInputError) as err:
        generic_model(tmp_path / "m.osim", 1.86, None, c3d, ModelSettings())
    text = str(err.value)
    assert text.startswith(f"{c3d}: no body mass: the plates do not carry the whole subject")
    assert "LANK, LHEE, LTOE, LMMAL" in text and "give mass_kg in the subject sheet" in text
    assert not (tmp_path / "m.osim").exists()
