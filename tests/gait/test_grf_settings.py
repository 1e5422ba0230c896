"""The ground-reaction stage's settings (gait.grf_settings): the ``grf`` keys to their fields, the rotation the
markers', the defaults the shipped config's, a missing key named; the events' resting-level rule is this one."""

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.stages.settings import stage_settings

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())


def _changed() -> dict:
    config = copy.deepcopy(CONFIG)
    config["grf"].update(loaded_threshold_n=35.0, resting_band_n=4.0, max_resting_n=60.0)
    config["markers"]["lab_to_model_rotation_deg"] = [0, 0, 90]
    return config


def test_every_config_key_reaches_its_field():
    """Threshold 35 N, band 4 N, resting limit 60 N; the rotation as floats, the markers' own."""
    settings = stage_settings(_changed(), "grf")
    assert settings == GRFSettings(rotation_deg=(0.0, 0.0, 90.0), threshold_n=35.0, band_n=4.0, max_rest_n=60.0)
    assert all(isinstance(v, float) for v in settings.rotation_deg)
    assert settings.rotation_deg == stage_settings(_changed(), "markers").rotation_deg


def test_the_shipped_config_gives_the_defaults():
    """20 N loaded, 10 N band, 100 N resting limit, Qualisys Z-up -> OpenSim Y-up."""
    assert stage_settings(CONFIG, "grf") == GRFSettings() == GRFSettings((-90.0, 0.0, 0.0), 20.0, 10.0, 100.0)


def test_the_events_take_the_resting_level_rule_from_here():
    events = stage_settings(_changed(), "events").events
    assert (events.band_n, events.max_rest_n) == (4.0, 60.0)


@pytest.mark.parametrize(
    ("section", "key"),
    [("grf", "loaded_threshold_n"), ("grf", "max_resting_n"), ("markers", "lab_to_model_rotation_deg")],
)
def test_a_missing_key_is_named(section, key):
    config = copy.deepcopy(CONFIG)
    del config[section][key]
    with pytest.raises(LoperInputError, match=f"^config: key '{section}.{key}' missing: "):
        stage_settings(config, "grf")
