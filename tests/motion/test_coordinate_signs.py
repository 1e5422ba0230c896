"""The sign of a coordinate in our convention, read from the model's kinematics: gait2392's knee is negative in
flexion, Rajagopal2016's positive, OpenSim's pelvis tilt positive front up."""

from __future__ import annotations

from pathlib import Path

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import read_model
from loper_analysis.motion.coordinate_signs import map_signs, require_map_signs
from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP
from loper_analysis.motion.model import build_lower_body_model

ROOT = Path(__file__).resolve().parents[2]
GAIT2392 = ROOT / "src" / "loper_analysis" / "templates" / "gait2392_simbody.osim"
RAJAGOPAL = ROOT / "tests" / "data" / "rajagopal2016" / "Rajagopal2016.osim"


def _lab_map(knee_sign: float) -> dict:
    cmap = {"pelvis_x": ("pelvis_tx", 1), "pelvis_angle": ("pelvis_tilt", -1)}
    for s, side in (("l", "left"), ("r", "right")):
        cmap |= {f"hip_{side}": (f"hip_flexion_{s}", 1), f"knee_{side}": (f"knee_angle_{s}", knee_sign)}
        cmap[f"ankle_{side}"] = (f"ankle_angle_{s}", 1)
    return cmap


def test_signs_of_the_generated_model_are_the_default_map():
    signs = map_signs(build_lower_body_model(1.75, 70.0), DEFAULT_COORDINATE_MAP)
    assert signs == {key: float(sign) for key, (_, sign) in DEFAULT_COORDINATE_MAP.items()}


@pytest.mark.parametrize(("model", "knee"), [(GAIT2392, -1.0), (RAJAGOPAL, 1.0)])
def test_knee_sign_differs_between_the_models_opensim_distributes(model, knee):
    signs = map_signs(read_model(model), _lab_map(1.0))
    assert signs["knee_left"] == signs["knee_right"] == knee
    assert signs["hip_left"] == signs["ankle_right"] == signs["pelvis_x"] == 1.0
    assert signs["pelvis_angle"] == -1.0


def test_a_knee_sign_that_contradicts_gait2392_stops_naming_the_key():
    model = read_model(GAIT2392)
    require_map_signs(model, _lab_map(-1.0), str(GAIT2392), "ik.coordinate_map")  # right: no error
    with pytest.raises(LoperInputError) as err:
        require_map_signs(model, _lab_map(1.0), str(GAIT2392), "ik.coordinate_map")
    text = str(err.value)
    assert "ik.coordinate_map.knee_left.sign: -1" in text and "ik.coordinate_map.knee_right.sign: -1" in text
    assert "knee_angle_l" in text and "hip_left" not in text
