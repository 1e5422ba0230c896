"""Device file steps: simulated logs written and read from disk, tables and figures, bad logs refused with nothing
written."""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.device.analysis import FRFSettings, StepSettings
from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.trials import DeviceTestSettings
from loper_analysis.errors import LoperInputError
from loper_analysis.io.robot_log import read_robot_log, write_robot_log
from loper_analysis.stages.device import step as device
from loper_analysis.stages.device.step import DeviceSettings
from loper_analysis.stages.settings import stage_settings

ROOT = Path(__file__).resolve().parents[3]

SHORT = DeviceTestSettings(broadband_duration_s=30.0, step_repetitions=3)
STEP_ARGS = (1000.0, (20.0, 40.0, 60.0), StepSettings(before_s=0.05, after_s=0.45, steady_window_s=(0.15, 0.3)))
FRF = FRFSettings(window_samples=5000, overlap_samples=50)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("raw")
    for trial in ("device-frf", "device-steps"):
        device.device_trial(d / f"{trial}.loper.tsv", "S01", trial, DeviceParameters(), FreeLeg(), SHORT, 3)
    return d


@pytest.fixture(scope="module")
def tables(logs, tmp_path_factory):
    """FRF, step metrics, averages and summary of the logs on disk; returns (directory, frf, metrics, summary)."""
    d = tmp_path_factory.mktemp("device")
    frf = device.frf(logs / "device-frf.loper.tsv", d / "frf.tsv", 1000.0, FRF)
    metrics = device.steps(logs / "device-steps.loper.tsv", d / "m.tsv", d / "a.tsv", *STEP_ARGS)
    summary = device.summary(d / "frf.tsv", d / "m.tsv", d / "s.tsv", (0.5, 2.0))
    return d, frf, metrics, summary


def test_frf_table_of_the_log_on_disk(tables):
    _, frf, _, _ = tables
    assert list(frf.columns) == ["frequency_hz", "gain", "phase_deg", "coherence"]
    np.testing.assert_allclose(frf.frequency_hz.iloc[0], 0.2)  # 1000 Hz / 5000 samples


def test_step_metrics_of_the_log_on_disk(tables):
    _, _, metrics, _ = tables
    assert list(metrics.columns[:4]) == ["amplitude_n", "n_repetitions", "rise_time_ms", "overshoot_pct"]
    assert (metrics.n_repetitions == 3).all()


def test_logs_on_disk_give_the_device_figures_of_the_study(tables):
    d, _, _, summary = tables
    s = summary.set_index("metric")
    assert {"bandwidth_hz", "rise_time_ms", "overshoot_pct"} <= set(s.index)
    assert list(summary.columns[:4]) == ["metric", "value", "study_value", "unit"]
    for metric in ("bandwidth_hz", "rise_time_ms", "overshoot_pct", "steady_state_40n_n"):
        assert abs(s.loc[metric, "difference_pct"]) <= 15.0, (metric, s.loc[metric, "value"])
    # the table on disk equals the returned one
    pd.testing.assert_frame_equal(pd.read_csv(d / "s.tsv", sep="\t"), summary, check_exact=False, rtol=1e-9)


def test_figures_step_writes_both_pngs(tables, tmp_path):
    d, _, _, _ = tables
    device.figures(d / "frf.tsv", d / "s.tsv", d / "a.tsv", tmp_path / "bode.png", tmp_path / "steps.png")
    for name in ("bode.png", "steps.png"):
        assert (tmp_path / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name


def test_a_step_trial_without_steps_is_refused_and_nothing_written(logs, tmp_path):
    frame, _meta = read_robot_log(logs / "device-steps.loper.tsv")
    frame["force_desired_n"] = 0.0
    frame["perturbation"] = 0
    bad = tmp_path / "no-steps.loper.tsv"
    write_robot_log(bad, frame, 1000.0)
    with pytest.raises(LoperInputError, match=r"no-steps\.loper\.tsv: no step found"):
        device.steps(bad, tmp_path / "m.tsv", tmp_path / "a.tsv", *STEP_ARGS)
    assert not (tmp_path / "m.tsv").exists() and not (tmp_path / "a.tsv").exists()


def test_a_log_with_nan_force_is_refused_naming_file_column_sample(logs, tmp_path):
    text = (logs / "device-frf.loper.tsv").read_text().splitlines()
    header_end = next(i for i, line in enumerate(text) if line.startswith("time_s"))
    cells = text[header_end + 101].split("\t")
    cells[2] = "nan"
    text[header_end + 101] = "\t".join(cells)
    bad = tmp_path / "nan.loper.tsv"
    bad.write_text("\n".join(text) + "\n")
    with pytest.raises(LoperInputError) as info:
        device.frf(bad, tmp_path / "frf.tsv", 1000.0, FRF)
    msg = str(info.value)
    assert "nan.loper.tsv" in msg and "force_measured_n" in msg and "sample 100" in msg, msg
    assert not (tmp_path / "frf.tsv").exists()


def test_declared_rate_must_match(logs, tmp_path):
    with pytest.raises(LoperInputError, match="sample_rate_hz"):
        device.frf(logs / "device-frf.loper.tsv", tmp_path / "frf.tsv", 500.0, FRF)
    assert not (tmp_path / "frf.tsv").exists()


# ---------------------------------------------------------------- the stage's settings from the config


def test_device_settings_of_the_shipped_config_are_the_library_defaults():
    """The device's numbers; which subject holds the device tests and how a .mat export is named are the
    study's choice (S01 and the robot's export names in the shipped config), no default of the library."""
    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    settings = stage_settings(config, "device")
    assert (settings.subject, settings.mat_column_map["force_measured_n"]) == ("S01", "Fm")
    assert dataclasses.replace(settings, subject=None, mat_column_map=None) == DeviceSettings()


def test_device_settings_from_config_take_each_section_to_its_part():
    config = copy.deepcopy(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    config["device"]["leg"]["mass_kg"] = 9.0
    config["device"]["tests"]["step_amplitudes_n"] = [30.0]
    config["device"]["analysis"]["welch_window_samples"] = 2000
    config["device"]["parameters"]["lever_arm_m"] = 0.6
    settings = stage_settings(config, "device")
    assert settings.leg.mass_kg == 9.0 and settings.tests.step_amplitudes_n == (30.0,)
    assert settings.analysis.frf == FRFSettings(window_samples=2000, overlap_samples=50)
    assert settings.parameters.lever_arm_m == 0.6
    assert settings.analysis.steps == StepSettings() and settings.tests.step_repetitions == 10
