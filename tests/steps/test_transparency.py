"""The settings of the transparency step (loper_analysis.steps.transparency): from the config and the defaults."""

from __future__ import annotations

import copy
from pathlib import Path

import yaml

from loper_analysis.gait.outliers import MIN_VALID_STRIDES
from loper_analysis.steps.transparency import TransparencySettings
from loper_analysis.study_design import PERTURBED_SIDE

CONFIG = yaml.safe_load((Path(__file__).resolve().parents[2] / "config" / "config.yaml").read_text())


def test_settings_of_the_config_and_the_defaults_agree():
    assert TransparencySettings.from_config(CONFIG) == TransparencySettings()
    assert (TransparencySettings().side, TransparencySettings().min_strides) == (PERTURBED_SIDE, MIN_VALID_STRIDES)


def test_settings_take_the_config_s_side_and_stride_minimum():
    config = copy.deepcopy(CONFIG)
    config["trials"]["perturbed_side"] = "right"
    config["strides"]["min_valid_strides"] = 7
    assert TransparencySettings.from_config(config) == TransparencySettings(side="right", min_strides=7)
