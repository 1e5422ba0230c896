"""The stages' settings objects as the rules build them: each option of the config reaches its field, and the
library's named constants behind the settings' defaults equal ``config/config.yaml`` (the settings types'
defaults themselves are checked stage by stage in ``tests/stages/test_settings.py``).
"""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis import filtering
from loper_analysis.constants import LAB_TO_MODEL_ROTATION_DEG
from loper_analysis.device import analysis
from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.gait import events, grf, resampling
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.gait.stride_settings import StrideSettings
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.motion import heading, markers, plausibility
from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.stages.settings import stage_settings
from loper_analysis.transparency import TransparencySettings

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())

#: library constant -> config key of the same value
CONSTANTS = {
    "filtering.CUTOFF_HZ": (filtering.CUTOFF_HZ, "markers.filter.cutoff_hz"),
    "filtering.ORDER": (filtering.ORDER, "markers.filter.order"),
    "markers.MAX_GAP_FRAMES": (markers.MAX_GAP_FRAMES, "markers.max_gap_frames"),
    "heading.MIN_TRAVEL_SPEED_M_PER_S": (heading.MIN_TRAVEL_SPEED_M_PER_S, "markers.min_travel_speed_m_per_s"),
    "plausibility.EXTENT_RANGE_M": (plausibility.EXTENT_RANGE_M, "markers.extent_range_m"),
    "constants.LAB_TO_MODEL_ROTATION_DEG": (LAB_TO_MODEL_ROTATION_DEG, "markers.lab_to_model_rotation_deg"),
    "events.THRESHOLD_ON_N": (events.THRESHOLD_ON_N, "events.threshold_on_n"),
    "events.THRESHOLD_OFF_N": (events.THRESHOLD_OFF_N, "events.threshold_off_n"),
    "events.MIN_STANCE_S": (events.MIN_STANCE_S, "events.min_stance_s"),
    "events.MIN_SWING_S": (events.MIN_SWING_S, "events.min_swing_s"),
    "grf.RESTING_BAND_N": (grf.RESTING_BAND_N, "grf.resting_band_n"),
    "grf.MAX_RESTING_N": (grf.MAX_RESTING_N, "grf.max_resting_n"),
    "resampling.N_POINTS": (resampling.N_POINTS, "strides.n_points"),
    "analysis.WELCH_WINDOW_SAMPLES": (analysis.WELCH_WINDOW_SAMPLES, "device.analysis.welch_window_samples"),
    "analysis.WELCH_OVERLAP_SAMPLES": (analysis.WELCH_OVERLAP_SAMPLES, "device.analysis.welch_overlap_samples"),
    "analysis.BANDWIDTH_REFERENCE_BAND_HZ": (
        analysis.BANDWIDTH_REFERENCE_BAND_HZ,
        "device.analysis.bandwidth_reference_band_hz",
    ),
    "analysis.STEP_BEFORE_S": (analysis.STEP_BEFORE_S, "device.analysis.step_before_s"),
    "analysis.STEP_AFTER_S": (analysis.STEP_AFTER_S, "device.analysis.step_after_s"),
    "analysis.STEADY_WINDOW_S": (analysis.STEADY_WINDOW_S, "device.analysis.steady_window_s"),
}


def _get(config: dict, path: str):
    node = config
    for key in path.split("."):
        node = node[key]
    return node


def _plain(value):
    """Lists and tuples alike (YAML has no tuples)."""
    return tuple(_plain(v) for v in value) if isinstance(value, list | tuple) else value


@pytest.mark.parametrize("name", CONSTANTS)
def test_library_constant_equals_the_config(name):
    value, key = CONSTANTS[name]
    assert _plain(value) == _plain(_get(CONFIG, key)), f"{name} = {value!r}, but {key} = {_get(CONFIG, key)!r}"


#: Each settings type and the stage's settings (and part of them) it is.
READ_AS = {
    MarkerSettings: ("markers", None),
    EventSettings: ("events", "events"),
    LoadcellSettings: ("events", "loadcell"),
    GRFSettings: ("grf", None),
    StrideSettings: ("strides", None),
    TransparencySettings: ("transparency", None),
}


def _read(settings_type, config: dict):
    stage, part = READ_AS[settings_type]
    settings = stage_settings(config, stage)
    return settings if part is None else getattr(settings, part)


@pytest.mark.parametrize(
    ("settings_type", "path", "field", "value"),
    [
        (MarkerSettings, "markers.max_gap_frames", "max_gap_frames", 3),
        (MarkerSettings, "markers.filter.cutoff_hz", "cutoff_hz", 12.0),
        (MarkerSettings, "markers.walking_direction", "walking_direction", "fixed"),
        (EventSettings, "events.threshold_on_n", "threshold_on_n", 80.0),
        (EventSettings, "grf.max_resting_n", "max_rest_n", 50.0),
        (EventSettings, "events.grf_channels", "grf_channels", {"left": "belt_l", "right": "belt_r"}),
        (LoadcellSettings, "events.sync_channel", "sync_channel", "trigger"),
        (LoadcellSettings, "markers.filter.order", "order", 2),
        (StrideSettings, "strides.min_valid_strides", "min_valid", 7),
        (StrideSettings, "study.perturbed_side", "side", "right"),
        (GRFSettings, "grf.loaded_threshold_n", "threshold_n", 35.0),
        (GRFSettings, "grf.resting_band_n", "band_n", 4.0),
        (TransparencySettings, "strides.min_valid_strides", "min_strides", 7),
        (TransparencySettings, "study.perturbed_side", "side", "right"),
    ],
)
def test_a_changed_config_key_reaches_its_field(settings_type, path, field, value):
    config = copy.deepcopy(CONFIG)
    *parents, key = path.split(".")
    _get(config, ".".join(parents))[key] = value
    assert getattr(_read(settings_type, config), field) == value
    assert getattr(settings_type(), field) != value


def test_the_static_trial_is_neither_filled_nor_filtered():
    static = stage_settings(CONFIG, "markers").for_static()
    assert (static.max_gap_frames, static.cutoff_hz) == (0, None)
    assert static.rotation_deg == tuple(CONFIG["markers"]["lab_to_model_rotation_deg"])
