"""The library's named constants and the keyword defaults of its functions agree with the shipped configuration
(``config/config.yaml``) and its schema.

The settings types' defaults are checked stage by stage against what each stage's reader builds of the shipped
config (``tests/stages/test_settings.py``). A function whose keyword stands for a config key (a fit's number of
starts, a window's length) and a constant the code names are paired here with their key, so that changing either
side alone fails.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
from pathlib import Path

import pytest
import yaml

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.impedance import identification
from loper_analysis.impedance.identification import (
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    PreparedWindow,
    identify_impedance,
    joint_status,
    prepare_window,
    refit_with_null_pairs,
)
from loper_analysis.impedance.identification.impedance import IdentificationSettings, impedance_rows
from loper_analysis.impedance.responses import ResponseSettings, match_unperturbed, too_short, window_outliers
from loper_analysis.impedance.responses.response_window import WINDOW_KEYS, ResponseWindow
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())


# --------------------------------------------------------------------------- helpers


def _plain(value):
    """Lists and tuples alike (YAML has no tuples), mappings recursively: a default and a config value compare."""
    if isinstance(value, list | tuple):
        return tuple(_plain(v) for v in value)
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _get(config: dict, path: str):
    node = config
    for key in path.split("."):
        node = node[key]
    return node


def _defaults(cls) -> dict:
    """Field -> default of a settings dataclass."""
    instance = cls()
    return {f.name: getattr(instance, f.name) for f in dataclasses.fields(cls)}


def _mismatches(defaults: dict, config: dict, keys: dict[str, str]) -> list[str]:
    """``name = default, but key = value`` for every name whose default differs from its config key (dotted)."""
    out = []
    for name, path in keys.items():
        have, want = _plain(defaults[name]), _plain(_get(config, path))
        if have != want:
            out.append(f"{name} = {have!r}, but {path} = {want!r}")
    return out


def _signature_defaults(function) -> dict:
    return {
        name: p.default
        for name, p in inspect.signature(function).parameters.items()
        if p.default is not inspect.Parameter.empty
    }


#: ResponseSettings field -> config key (as the workflow's impedance_fit rule passes them; the window aside:
#: a ResponseWindow, whose fields map to their keys by WINDOW_KEYS).
RESPONSE_KEYS = {
    "whisker": "strides.iqr_whisker",
    "max_fraction": "strides.max_outlier_fraction",
    "min_strides": "strides.min_valid_strides",
    "counterfactual": "impedance.counterfactual",
}
#: IdentificationSettings field -> config key: the same name under ``identification`` (as the impedance_fit rule
#: passes them), except ``plausible_ranges`` (default None stands for DEFAULT_PLAUSIBLE_RANGES) and ``seed``.
IDENTIFICATION_KEYS = {
    f.name: f"impedance.{f.name}"
    for f in dataclasses.fields(IdentificationSettings)
    if f.name not in ("plausible_ranges", "seed")
}
# --------------------------------------------------------------------------- device


def test_device_parameters_schema_names_are_the_dataclass_fields():
    fields = {f.name for f in dataclasses.fields(DeviceParameters)}
    schema = SCHEMA["properties"]["device"]["properties"]["parameters"]
    assert set(schema["properties"]) == fields
    assert set(schema["required"]) == fields
    assert schema["additionalProperties"] is False


# --------------------------------------------------------------------------- responses and identification


def test_every_identification_key_has_a_checked_default():
    checked = set(IDENTIFICATION_KEYS.values()) | {v for v in RESPONSE_KEYS.values() if v.startswith("impedance.")}
    checked |= set(WINDOW_KEYS.values())
    checked |= {"impedance.plausible_ranges"}
    assert {f"impedance.{k}" for k in CONFIG["impedance"]} == checked


def test_identification_constants_equal_config_identification():
    constants = {
        "WINDOW_BEFORE_S": "impedance.window_before_s",
        "WINDOW_AFTER_S": "impedance.window_after_s",
        "INITIAL_STATE_SPAN_S": "impedance.initial_state_span_s",
        "INITIAL_STATE_DEGREE": "impedance.initial_state_degree",
        "N_SUBSTEPS": "impedance.n_substeps",
        "N_STARTS": "impedance.n_starts",
        "FIT_TOLERANCE": "impedance.tolerance",
        "MERGE_TOLERANCE": "impedance.merge_tolerance",
        "NULL_PAIR_COMPONENTS": "impedance.null_pair_components",
        "MIN_NULL_PAIRS": "impedance.min_null_pairs",
        "STIFFNESS_BOUNDS_NM_PER_RAD": "impedance.stiffness_bounds_nm_per_rad",
        "DAMPING_BOUNDS_NMS_PER_RAD": "impedance.damping_bounds_nms_per_rad",
        "MAX_CI_FRACTION": "impedance.max_ci_fraction",
        "MIN_VAF_PCT": "impedance.min_vaf_pct",
    }
    values = {name: getattr(identification, name) for name in constants}
    assert _mismatches(values, CONFIG, constants) == []
    k, d = (
        CONFIG["impedance"]["stiffness_bounds_nm_per_rad"],
        CONFIG["impedance"]["damping_bounds_nms_per_rad"],
    )
    assert DEFAULT_LOWER.tolist() == [k[0], d[0]] * 3
    assert DEFAULT_UPPER.tolist() == [k[1], d[1]] * 3


#: Functions whose keyword defaults stand for config keys: keyword -> config key.
KEYWORD_DEFAULTS = [
    (
        prepare_window,
        {
            "n_substeps": "impedance.n_substeps",
            "initial_state_degree": "impedance.initial_state_degree",
        },
    ),
    (
        identify_impedance,
        {
            "n_starts": "impedance.n_starts",
            "tolerance": "impedance.tolerance",
            "merge_tolerance": "impedance.merge_tolerance",
        },
    ),
    (
        refit_with_null_pairs,
        {
            "n_components": "impedance.null_pair_components",
            "min_null_pairs": "impedance.min_null_pairs",
        },
    ),
    (
        joint_status,
        {"max_ci_fraction": "impedance.max_ci_fraction", "min_vaf_pct": "impedance.min_vaf_pct"},
    ),
    (
        impedance_rows,
        {"max_ci_fraction": "impedance.max_ci_fraction", "min_vaf_pct": "impedance.min_vaf_pct"},
    ),
    (
        window_outliers,
        {
            "before_s": "impedance.window_before_s",
            "after_s": "impedance.window_after_s",
            "whisker": "strides.iqr_whisker",
            "max_fraction": "strides.max_outlier_fraction",
        },
    ),
    (too_short, {"window_after_s": "impedance.window_after_s"}),
    (match_unperturbed, {"before_s": "impedance.window_before_s"}),
]


@pytest.mark.parametrize(("function", "keys"), KEYWORD_DEFAULTS, ids=[f.__name__ for f, _ in KEYWORD_DEFAULTS])
def test_keyword_defaults_equal_config(function, keys):
    assert _mismatches(_signature_defaults(function), CONFIG, keys) == []


def test_prepare_window_default_window_is_the_configs():
    assert _signature_defaults(prepare_window)["window"] == stage_settings(CONFIG, "impedance").response.window


def test_prepared_window_and_identify_defaults_agree_with_config():
    fields = {f.name: f.default for f in dataclasses.fields(PreparedWindow)}
    keys = {
        "initial_state_span_s": "impedance.initial_state_span_s",
        "initial_state_degree": "impedance.initial_state_degree",
    }
    assert _mismatches(fields, CONFIG, keys) == []
    fit = _signature_defaults(identify_impedance)
    assert fit["lower"] is DEFAULT_LOWER and fit["upper"] is DEFAULT_UPPER
    rows = _signature_defaults(impedance_rows)
    k, d = (
        CONFIG["impedance"]["stiffness_bounds_nm_per_rad"],
        CONFIG["impedance"]["damping_bounds_nms_per_rad"],
    )
    assert _plain(rows["lower"]) == (k[0], d[0]) and _plain(rows["upper"]) == (k[1], d[1])


# --------------------------------------------------------------------------- validation and planning


# --------------------------------------------------------------------------- synthetic lab


# analog_rate_hz (1024 Hz) and robot_margin_s (2 s) are properties of the simulated lab only


# --------------------------------------------------------------------------- the checks can fail


@pytest.mark.parametrize(
    ("path", "value"),
    [
        ("impedance.window_before_s", 0.03),
        ("strides.iqr_whisker", 2.0),
        ("device.parameters.lead_time_s", 0.018),
    ],
)
def test_a_changed_config_value_is_a_mismatch(path, value):
    config = copy.deepcopy(CONFIG)
    *parents, key = path.split(".")
    _get(config, ".".join(parents))[key] = value
    keys = {
        **RESPONSE_KEYS,
        **{f"window.{n}": key for n, key in WINDOW_KEYS.items()},
        **{f"device.{n}": f"device.parameters.{n}" for n in CONFIG["device"]["parameters"]},
    }
    defaults = {
        **_defaults(ResponseSettings),
        **{f"window.{k}": v for k, v in _defaults(ResponseWindow).items()},
        **{f"device.{k}": v for k, v in _defaults(DeviceParameters).items()},
    }
    assert _mismatches(defaults, CONFIG, keys) == []
    (line,) = _mismatches(defaults, config, keys)
    assert path in line and repr(value) in line


def test_a_changed_default_is_a_mismatch():
    changed = _defaults(IdentificationSettings) | {"n_starts": 11}
    assert _mismatches(changed, CONFIG, IDENTIFICATION_KEYS) == ["n_starts = 11, but impedance.n_starts = 10"]
    device = _defaults(DeviceParameters) | {"servo_delay_s": 0.003}
    keys = {n: f"device.parameters.{n}" for n in device}
    assert _mismatches(device, CONFIG, keys) == ["servo_delay_s = 0.003, but device.parameters.servo_delay_s = 0.002"]
