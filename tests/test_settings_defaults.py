"""Library defaults agree with the shipped configuration (``config/config.yaml``) and its schema.

A setting is written in the config (what the workflow passes) and as a default in the library (what a direct
call gets). Each test pairs the defaults of one settings class with the config keys the workflow fills it from,
so that changing either side alone fails here. A default without a config key, or one that differs from the
config on purpose, is named and asserted explicitly.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
from pathlib import Path

import pytest
import yaml

from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.trials import DeviceTestSettings
from loper_analysis.impedance import identification
from loper_analysis.impedance.identification import (
    DEFAULT_LOWER,
    DEFAULT_PLAUSIBLE_RANGES,
    DEFAULT_UPPER,
    PreparedWindow,
    identify_impedance,
    joint_status,
    prepare_window,
    refit_with_null_pairs,
)
from loper_analysis.impedance.identification.impedance import IdentificationSettings, impedance_rows
from loper_analysis.impedance.identification.validation import ValidationSettings
from loper_analysis.impedance.responses import ResponseSettings, match_unperturbed, too_short, window_outliers
from loper_analysis.impedance.responses.response_window import WINDOW_KEYS, ResponseWindow
from loper_analysis.planning.window import PlanSettings
from loper_analysis.stages.settings import stage_settings
from loper_analysis.synthetic.lab_session import LabSessionSettings
from loper_analysis.synthetic.trials import LabSettings, PerturbationSettings

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
#: LabSettings field -> config key (as LabSettings.from_config reads them for the workflow).
LAB_KEYS = {
    "marker_noise_sd_m": "synthetic.marker_noise_sd_m",
    "n_gaps": "synthetic.marker_gaps_per_trial",
    "max_gap_frames": "synthetic.max_gap_frames",
    "grf_noise_sd_n": "synthetic.grf_noise_sd_n",
    "clock_offset_s": "synthetic.clock_offset_s",
    "clock_drift_ppm": "synthetic.clock_drift_ppm",
    "lab_to_model_rotation_deg": "markers.lab_to_model_rotation_deg",
    "sync_channel": "events.sync_channel",
}


# --------------------------------------------------------------------------- device


def test_device_parameters_defaults_equal_config_device_parameters():
    fields = [f.name for f in dataclasses.fields(DeviceParameters)]
    assert len(fields) == 24
    assert sorted(CONFIG["device"]["parameters"]) == sorted(fields)
    keys = {name: f"device.parameters.{name}" for name in fields}
    assert _mismatches(_defaults(DeviceParameters), CONFIG, keys) == []
    assert DeviceParameters(**CONFIG["device"]["parameters"]) == DeviceParameters()


def test_device_parameters_schema_names_are_the_dataclass_fields():
    fields = {f.name for f in dataclasses.fields(DeviceParameters)}
    schema = SCHEMA["properties"]["device"]["properties"]["parameters"]
    assert set(schema["properties"]) == fields
    assert set(schema["required"]) == fields
    assert schema["additionalProperties"] is False


def test_free_leg_and_device_test_defaults_equal_config():
    leg = [f.name for f in dataclasses.fields(FreeLeg)]
    assert sorted(CONFIG["device"]["leg"]) == sorted(leg)
    assert set(SCHEMA["properties"]["device"]["properties"]["leg"]["properties"]) == set(leg)
    assert _mismatches(_defaults(FreeLeg), CONFIG, {n: f"device.leg.{n}" for n in leg}) == []
    tests = [f.name for f in dataclasses.fields(DeviceTestSettings)]
    assert sorted(CONFIG["device"]["tests"]) == sorted(tests)
    assert _mismatches(_defaults(DeviceTestSettings), CONFIG, {n: f"device.tests.{n}" for n in tests}) == []


# --------------------------------------------------------------------------- responses and identification


def test_response_window_defaults_equal_config_identification():
    assert WINDOW_KEYS == {
        "before_s": "impedance.window_before_s",
        "after_s": "impedance.window_after_s",
        "initial_state_span_s": "impedance.initial_state_span_s",
    }
    assert _mismatches(_defaults(ResponseWindow), CONFIG, WINDOW_KEYS) == []
    assert stage_settings(CONFIG, "impedance").response.window == ResponseWindow()


def test_response_settings_defaults_equal_config_identification_and_strides():
    defaults = _defaults(ResponseSettings)
    assert _mismatches(defaults, CONFIG, RESPONSE_KEYS) == []
    assert defaults["window"] == ResponseWindow()
    # rate_hz has no config key (the workflow leaves it at its default): the response grid runs at the study's
    # motion-capture rate, the rate of the validation's simulated measurements and of the synthetic lab's markers
    assert set(defaults) - set(RESPONSE_KEYS) == {"rate_hz", "window"}
    assert defaults["rate_hz"] == CONFIG["validation"]["sample_rate_hz"] == LabSettings().marker_rate_hz


def test_identification_settings_defaults_equal_config_identification():
    defaults = _defaults(IdentificationSettings)
    assert _mismatches(defaults, CONFIG, IDENTIFICATION_KEYS) == []
    # plausible_ranges: None stands for DEFAULT_PLAUSIBLE_RANGES, which must be the config's ranges
    assert defaults["plausible_ranges"] is None
    config_ranges = {
        joint: (tuple(r["stiffness_nm_per_rad"]), tuple(r["damping_nms_per_rad"]))
        for joint, r in CONFIG["impedance"]["plausible_ranges"].items()
    }
    assert _plain(DEFAULT_PLAUSIBLE_RANGES) == config_ranges
    # seed differs on purpose: the workflow passes the config's seed; the library default follows
    # identify_impedance's own seed (0), so that the default settings fit as a bare identify_impedance call does
    assert defaults["seed"] == _signature_defaults(identify_impedance)["seed"] == 0
    assert defaults["seed"] != CONFIG["seed"]


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


def test_validation_settings_defaults_equal_validation_settings_of_config():
    given = {
        f.name: getattr(stage_settings(CONFIG, "validation"), f.name) for f in dataclasses.fields(ValidationSettings)
    }
    defaults = _defaults(ValidationSettings)
    different = [
        f"{k} = {defaults[k]!r}, config gives {v!r}" for k, v in given.items() if _plain(defaults[k]) != _plain(v)
    ]
    assert different == []
    # reference_cutoff_hz has no config key: the study fits the unfiltered reference (None)
    assert defaults["reference_cutoff_hz"] is None


def test_plan_settings_defaults_equal_config():
    keys = {
        "pulse_force_n": "planning.pulse_force_n",
        "pulse_duration_s": "planning.pulse_duration_s",
        **{
            name: f"impedance.{name}"
            for name in (
                "initial_state_degree",
                "n_substeps",
                "null_pair_components",
                "min_null_pairs",
                "interval_scatter",
                "stiffness_bounds_nm_per_rad",
                "damping_bounds_nms_per_rad",
            )
        },
        # the load cell's low-pass is the walking trials' filter; the pulse reaches the fit at the robot-log rate,
        # which is the device's control rate
        "force_cutoff_hz": "markers.filter.cutoff_hz",
        "force_order": "markers.filter.order",
        "force_rate_hz": "device.parameters.sample_rate_hz",
    }
    defaults = _defaults(PlanSettings)
    assert set(defaults) == set(keys) | {"window"}
    assert _mismatches(defaults, CONFIG, keys) == []
    assert defaults["window"] == stage_settings(CONFIG, "impedance").response.window


# --------------------------------------------------------------------------- synthetic lab


def test_lab_settings_defaults_equal_config_synthetic():
    defaults = _defaults(LabSettings)
    assert _mismatches(defaults, CONFIG, LAB_KEYS) == []
    # no config key of their own; each agrees with the config value it stands for
    unmapped = set(defaults) - set(LAB_KEYS)
    assert unmapped == {"marker_rate_hz", "analog_rate_hz", "robot_rate_hz", "robot_margin_s", "grf_prefix"}
    assert defaults["robot_rate_hz"] == CONFIG["device"]["parameters"]["sample_rate_hz"]  # robot log = control rate
    assert defaults["marker_rate_hz"] == CONFIG["validation"]["sample_rate_hz"]  # the study's motion-capture rate
    channels = CONFIG["events"]["grf_channels"]
    assert tuple(f"Fz{suffix}" for suffix in defaults["grf_prefix"]) == (channels["left"], channels["right"])
    # analog_rate_hz (1024 Hz) and robot_margin_s (2 s) are properties of the simulated lab only


def test_perturbation_settings_defaults_equal_config_synthetic():
    defaults = {f.name: f.default for f in dataclasses.fields(PerturbationSettings)}
    keys = {
        "force_n": "synthetic.pulse_force_n",
        "duration_s": "synthetic.pulse_duration_s",
        "every_strides": "synthetic.perturb_every_strides",
    }
    assert _mismatches(defaults, CONFIG, keys) == []


#: LabSessionSettings field -> config key (as LabSessionSettings.from_config reads them for the workflow).
LAB_SESSION_KEYS = {
    "seed": "seed",
    "static_duration_s": "synthetic.static_duration_s",
    "walking_duration_s": "synthetic.walking_duration_s",
    "timing_cv": "synthetic.timing_cv",
    "amplitude_cv": "synthetic.amplitude_cv",
    "pulse_force_n": "synthetic.pulse_force_n",
    "pulse_duration_s": "synthetic.pulse_duration_s",
    "perturb_every_strides": "synthetic.perturb_every_strides",
    "variability": "synthetic.variability",
    "adaptation_amplitude_change": "synthetic.device_adaptation.amplitude_change",
    "adaptation_offset_rad": "synthetic.device_adaptation.offset_rad",
    "adaptation_swing_gain": "synthetic.device_adaptation.swing_gain",
}


def test_lab_session_settings_defaults_equal_config_synthetic():
    defaults = _defaults(LabSessionSettings)
    assert _mismatches(defaults, CONFIG, LAB_SESSION_KEYS) == []
    # the composed settings have their own checks (the design, the lab, the device); the study variability's
    # fields are named as the config's but for the timing; the true impedance is the study's choice (None: none)
    assert set(defaults) - set(LAB_SESSION_KEYS) == {"design", "lab", "device", "study_variability", "truth"}
    v, config = defaults["study_variability"], CONFIG["synthetic"]["study_variability"]
    names = ("amplitude_cv", "offset_sd_rad", "timing_sd_stride", "swing_gain", "knots_per_stride")
    ours = (v.amplitude_cv, v.offset_sd_rad, v.timing_sd, v.swing_gain, v.knots_per_stride)
    assert _plain(ours) == _plain(tuple(config[k] for k in names))


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
