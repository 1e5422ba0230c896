"""The analysis window around an onset (``responses/response_window.py``): read from the config in one place,
held alike by the responses, the planner and the validation study, and refused with its key and value."""

from __future__ import annotations

import copy
import math
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.response_window import (
    INITIAL_STATE_SPAN_S,
    WINDOW_AFTER_S,
    WINDOW_BEFORE_S,
    ResponseWindow,
)
from loper_analysis.planning.window import PlanSettings
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def _config(before_s: float, after_s: float, span_s: float) -> dict:
    config = copy.deepcopy(CONFIG)
    config["impedance"].update(window_before_s=before_s, window_after_s=after_s, initial_state_span_s=span_s)
    return config


def test_from_config_reads_the_three_keys():
    window = stage_settings(_config(0.03, 0.4, 0.12), "impedance").response.window
    assert (window.before_s, window.after_s, window.initial_state_span_s) == (0.03, 0.4, 0.12)


def test_the_defaults_are_the_shipped_configs():
    assert (WINDOW_BEFORE_S, WINDOW_AFTER_S, INITIAL_STATE_SPAN_S) == (0.025, 0.25, 0.1)
    assert stage_settings(CONFIG, "impedance").response.window == ResponseWindow(0.025, 0.25, 0.1) == ResponseWindow()


def test_fit_planner_and_validation_hold_the_one_window_of_the_config():
    config = _config(0.03, 0.4, 0.12)
    window = ResponseWindow(before_s=0.03, after_s=0.4, initial_state_span_s=0.12)
    assert stage_settings(config, "impedance").response.window == window
    assert stage_settings(config, "planning").plan.window == window
    assert stage_settings(config, "validation").window == window


@pytest.mark.parametrize(
    ("field", "key", "value"),
    [
        ("before_s", "impedance.window_before_s", -0.01),
        ("after_s", "impedance.window_after_s", -0.1),
        ("initial_state_span_s", "impedance.initial_state_span_s", math.inf),
        ("after_s", "impedance.window_after_s", math.nan),
    ],
)
def test_a_bad_field_is_refused_naming_its_key_and_value(field, key, value):
    with pytest.raises(LoperInputError) as info:
        ResponseWindow(**{field: value})
    assert str(info.value) == f"{key} must be a finite number >= 0.0, got {float(value)!r}"


def test_a_bad_config_value_is_refused_by_from_config_naming_the_key():
    with pytest.raises(LoperInputError, match=r"^impedance\.initial_state_span_s .* got -0\.5$"):
        _ = stage_settings(_config(0.025, 0.25, -0.5), "impedance").response.window


def test_a_pulse_as_long_as_the_window_after_the_onset_is_seen_whole():
    ResponseWindow(after_s=0.25).check_pulse(0.25)


def test_a_pulse_longer_than_the_window_after_the_onset_is_refused():
    with pytest.raises(LoperInputError) as info:
        ResponseWindow(after_s=0.25).check_pulse(0.3)
    assert str(info.value) == (
        "pulse_duration_s = 0.3 s is longer than the fit window after the onset "
        "(impedance.window_after_s = 0.25 s): the fit would not see its end"
    )
    with pytest.raises(LoperInputError, match=r"^pulse_duration_s must be > 0 s, got 0 s$"):
        ResponseWindow().check_pulse(0.0)


def test_the_planner_refuses_a_pulse_past_its_window():
    with pytest.raises(LoperInputError, match=r"impedance\.window_after_s = 0\.2 s"):
        PlanSettings(pulse_duration_s=0.21, window=ResponseWindow(after_s=0.2))


def test_a_window_inside_the_swing_passes_up_to_its_ends():
    # onset 0.05 s into a 0.6 s swing: at most 0.05 s before and 0.55 s after the onset
    ResponseWindow(before_s=0.05, after_s=0.55).check_in_swing(0.05, 0.6)


@pytest.mark.parametrize(
    ("window", "onset_s", "swing_s", "expected"),
    [
        (ResponseWindow(after_s=0.56), 0.05, 0.6, "impedance.window_after_s = 0.56 s does not fit"),
        (ResponseWindow(after_s=0.56), 0.05, 0.6, "at most 0.55 s (validation.swing_duration_s = 0.6 s"),
        (ResponseWindow(before_s=0.06), 0.05, 0.6, "impedance.window_before_s = 0.06 s does not fit"),
        (ResponseWindow(before_s=0.06), 0.05, 0.6, "at most 0.05 s (validation.onset_s)"),
        (ResponseWindow(), 0.7, 0.6, "validation.onset_s = 0.7 s lies outside the simulated swing 0 .. 0.6 s"),
        (ResponseWindow(), 0.05, 0.0, "validation.swing_duration_s must be positive, got 0 s"),
    ],
)
def test_a_window_outside_the_swing_is_refused_naming_key_value_and_limit(window, onset_s, swing_s, expected):
    with pytest.raises(LoperInputError) as info:
        window.check_in_swing(onset_s, swing_s)
    assert expected in str(info.value)
