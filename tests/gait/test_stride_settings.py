"""The strides stage's settings (gait.stride_settings): the ``strides`` keys to their fields, the leg the study
design's, the defaults the shipped config's, a missing key named."""

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.stages.settings import stage_settings

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())


def test_every_config_key_reaches_its_field():
    config = copy.deepcopy(CONFIG)
    config["strides"].update(n_points=51, iqr_whisker=2.0, max_outlier_fraction=0.2, min_valid_strides=7)
    config["study"]["perturbed_side"] = "right"
    assert stage_settings(config, "strides") == StrideSettings(
        side="right", n_points=51, whisker=2.0, max_fraction=0.2, min_valid=7
    )


def test_the_shipped_config_gives_the_defaults():
    """The left leg, 101 samples per cycle, the IQR rule of 1.5 IQR and 20 %, at least 5 kept strides."""
    assert stage_settings(CONFIG, "strides") == StrideSettings() == StrideSettings("left", 101, 1.5, 0.2, 5)


@pytest.mark.parametrize(("section", "key"), [("strides", "n_points"), ("study", "perturbed_side")])
def test_a_missing_key_is_named(section, key):
    config = copy.deepcopy(CONFIG)
    del config[section][key]
    with pytest.raises(LoperInputError, match=f"^config: key '{section}.{key}' missing: "):
        stage_settings(config, "strides")
