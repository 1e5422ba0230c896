"""The simulated lab's settings (synthetic.lab_session): the defaults the config's, every key they read to its
field (through the lab's, the design's and the device's own ``from_config``), a missing or bad key named."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from pathlib import Path

import pytest
import yaml

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from loper_analysis.synthetic.lab_session import (
    STATIC_TRIAL_DURATION_S,
    VARIABILITY,
    WALKING_TRIAL_DURATION_S,
    LabSessionSettings,
)
from loper_analysis.synthetic.trials import LabSettings
from loper_analysis.synthetic.variability import lab_variability
from tests.lab_export_session import LabExportSettings

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def test_the_defaults_are_the_configs():
    assert stage_settings(CONFIG, "synthetic").lab == LabSettings()
    # the true impedance is the study's choice (no default of the library): the config's, inside the fit's bounds
    settings = stage_settings(CONFIG, "synthetic")
    assert settings.truth.stiffness_nm_per_rad["50"] == [55.0, 3.0, 8.0] and settings.truth.between_subject_cv == 0.15
    assert settings.truth.stiffness_bounds_nm_per_rad == (0.0, 200.0)
    assert dataclasses.replace(settings, truth=None) == LabSessionSettings()
    assert LabExportSettings.from_config(CONFIG) == LabExportSettings()


def test_from_config_reads_every_key_it_maps():
    config = copy.deepcopy(CONFIG)
    s = config["synthetic"]
    config["seed"] = 7
    config["study"]["no_device"] = "walk-free"
    config["markers"]["lab_to_model_rotation_deg"] = [0.0, 0.0, 0.0]
    config["events"]["sync_channel"] = "trigger"
    config["device"]["parameters"]["servo_delay_s"] = 0.003
    config["model"]["brace_attachment_fraction"] = 0.7
    s.update(
        walking_duration_s=30.0,
        static_duration_s=1.5,
        variability="gentle",
        timing_cv=0.02,
        amplitude_cv=0.04,
        marker_gaps_per_trial=5,
        clock_drift_ppm=-20.0,
        pulse_force_n=30.0,
        pulse_duration_s=0.08,
        perturb_every_strides=[2, 4],
    )
    s["study_variability"]["knots_per_stride"] = 6
    s["device_adaptation"]["offset_rad"] = [0.01, 0.02, 0.03]
    got = stage_settings(config, "synthetic")
    assert got.seed == 7 and got.design.no_device == "walk-free"
    assert got.lab == dataclasses.replace(
        LabSettings(),
        lab_to_model_rotation_deg=(0.0, 0.0, 0.0),
        sync_channel="trigger",
        n_gaps=5,
        clock_drift_ppm=-20.0,
    )
    assert got.device == DeviceParameters(**config["device"]["parameters"]) and got.device.servo_delay_s == 0.003
    assert (got.walking_duration_s, got.static_duration_s, got.timing_cv, got.amplitude_cv) == (30.0, 1.5, 0.02, 0.04)
    assert (got.pulse_force_n, got.pulse_duration_s, got.perturb_every_strides) == (30.0, 0.08, (2, 4))
    assert got.variability == "gentle" and got.study_variability.knots_per_stride == 6
    assert got.adaptation_offset_rad == (0.01, 0.02, 0.03)
    export = LabExportSettings.from_config(config)
    assert export.brace_fraction == 0.7 and export.seed == 7 and export.lab == got.lab
    # a rule's params: Snakemake pickles them for the script and compares their repr between runs
    assert pickle.loads(pickle.dumps(got)) == got and repr(stage_settings(config, "synthetic")) == repr(got)


def test_the_variability_is_the_one_the_config_section_gives():
    true = {o: {j: {"K": 10.0 + o, "D": 0.5} for j in ("hip", "knee", "ankle")} for o in (50, 175, 300)}
    ours = lab_variability(stage_settings(CONFIG, "synthetic").variability_settings(), 2024, "S01", true)
    assert ours == lab_variability(CONFIG["synthetic"], 2024, "S01", true)
    assert all(x is not None for x in ours)
    gentle = dataclasses.replace(LabSessionSettings(), variability="gentle")
    assert lab_variability(gentle.variability_settings(), 2024, "S01", true) == (None, None, None)


def test_the_named_defaults():
    """A static trial of 2 s, walking trials of 45 s, the study's variability."""
    assert (STATIC_TRIAL_DURATION_S, WALKING_TRIAL_DURATION_S, VARIABILITY) == (2.0, 45.0, "study")
    default = LabSessionSettings()
    assert (default.static_duration_s, default.walking_duration_s, default.variability) == (2.0, 45.0, "study")


@pytest.mark.parametrize(
    ("path", "key"),
    [
        (("synthetic", "timing_cv"), "timing_cv"),
        (("synthetic", "device_adaptation"), "device_adaptation"),
        (("seed",), "seed"),
    ],
)
def test_a_missing_key_is_named(path, key):
    config = copy.deepcopy(CONFIG)
    node = config
    for name in path[:-1]:
        node = node[name]
    del node[path[-1]]
    with pytest.raises(LoperInputError, match=f"^config: key '{'.'.join(path)}' missing: "):
        stage_settings(config, "synthetic")


def test_a_bad_device_parameter_is_named():
    config = copy.deepcopy(CONFIG)
    config["device"]["parameters"]["servo_delay_s"] = -0.002
    with pytest.raises(LoperInputError, match="^device parameter servo_delay_s must be >= 0, got -0.002$"):
        stage_settings(config, "synthetic")
