"""The simulated lab's file steps (steps/synthetic.py): their settings from the config, the session's files by
trial, and a short session written to disk."""

from __future__ import annotations

import copy
import dataclasses
import pickle
from pathlib import Path

import pytest
import yaml

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.robot_log import read_robot_log
from loper_analysis.steps.synthetic import (
    LabSessionFiles,
    LabSessionSettings,
    SyntheticLabSettings,
    lab_session,
    truth,
)
from loper_analysis.study_design import StudyDesign
from loper_analysis.synthetic.subjects import subject_anthropometry
from loper_analysis.synthetic.trials import LabSettings
from loper_analysis.synthetic.variability import lab_variability
from tests.lab_export_session import LabExportSettings

ROOT = Path(__file__).resolve().parents[2]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def test_the_defaults_are_the_configs():
    assert LabSettings.from_config(CONFIG) == LabSettings()
    assert SyntheticLabSettings.from_config(CONFIG) == SyntheticLabSettings()
    assert LabSessionSettings.from_config(CONFIG) == LabSessionSettings()
    assert LabExportSettings.from_config(CONFIG) == LabExportSettings()


def test_from_config_reads_every_key_it_maps():
    config = copy.deepcopy(CONFIG)
    s = config["synthetic"]
    config["seed"] = 7
    config["trials"]["no_device"] = "walk-free"
    config["markers"]["lab_to_model_rotation_deg"] = [0.0, 0.0, 0.0]
    config["events"]["sync_channel"] = "trigger"
    config["device"]["parameters"]["servo_delay_s"] = 0.003
    config["opensim"]["brace_attachment_fraction"] = 0.7
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
    got = LabSessionSettings.from_config(config)
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
    assert pickle.loads(pickle.dumps(got)) == got and repr(LabSessionSettings.from_config(config)) == repr(got)


def test_the_variability_is_the_one_the_config_section_gives():
    true = {o: {j: {"K": 10.0 + o, "D": 0.5} for j in ("hip", "knee", "ankle")} for o in (50, 175, 300)}
    ours = lab_variability(LabSessionSettings.from_config(CONFIG).variability_settings(), 2024, "S01", true)
    assert ours == lab_variability(CONFIG["synthetic"], 2024, "S01", true)
    assert all(x is not None for x in ours)
    gentle = dataclasses.replace(LabSessionSettings(), variability="gentle")
    assert lab_variability(gentle.variability_settings(), 2024, "S01", true) == (None, None, None)


def test_the_rules_file_lists_by_trial():
    design = StudyDesign(perturbation_onsets_ms=(50,), perturbation_repeats=1)
    files = LabSessionFiles.in_design_order(design, "t.yaml", "s.c3d", ["a.c3d", "b.c3d", "c.c3d"], ["b.tsv", "c.tsv"])
    assert files.c3d == {"walk-nodevice": "a.c3d", "walk-device": "b.c3d", "pert050-1": "c.c3d"}
    assert files.robot_logs == {"walk-device": "b.tsv", "pert050-1": "c.tsv"}
    with pytest.raises(ValueError):  # a list that does not match the design
        LabSessionFiles.in_design_order(design, "t.yaml", "s.c3d", ["a.c3d", "b.c3d"], ["b.tsv", "c.tsv"])
    with pytest.raises(LoperInputError, match="pert175-1"):
        LabSessionFiles("t.yaml", "s.c3d", {"walk-device": "b.c3d"}, {"pert175-1": "x.tsv"})


def test_a_short_session_on_disk(tmp_path):
    config = copy.deepcopy(CONFIG)
    config["trials"].update(perturbation_onsets_ms=[50], perturbation_repeats=1)
    config["synthetic"]["walking_duration_s"] = 10.0
    settings = LabSessionSettings.from_config(config)
    row = subject_anthropometry({"subject": "S09", "source": "synthetic"}, settings.seed)
    s = config["synthetic"]
    ident = config["identification"]
    truth(
        tmp_path / "truth.yaml",
        row,
        s["stiffness_nm_per_rad"],
        s["damping_nms_per_rad"],
        s["between_subject_cv"],
        ident["stiffness_bounds_nm_per_rad"],
        ident["damping_bounds_nms_per_rad"],
        settings.seed,
    )
    trials = settings.design.walking_trials()
    files = LabSessionFiles.in_design_order(
        settings.design,
        tmp_path / "truth.yaml",
        tmp_path / "static.c3d",
        [tmp_path / f"{t}.c3d" for t in trials],
        [tmp_path / f"{t}.loper.tsv" for t in trials if t != "walk-nodevice"],
    )
    lab_session("S09", row, files, settings)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "pert050-1.c3d",
        "pert050-1.loper.tsv",
        "static.c3d",
        "truth.yaml",
        "walk-device.c3d",
        "walk-device.loper.tsv",
        "walk-nodevice.c3d",
    ]
    walking = read_c3d(tmp_path / "pert050-1.c3d")
    assert walking.markers_m.shape[0] == round(10.0 * settings.lab.marker_rate_hz)
    assert read_c3d(tmp_path / "static.c3d").markers_m.shape[0] == round(s["static_duration_s"] * 128.0)
    robot, header = read_robot_log(tmp_path / "pert050-1.loper.tsv", settings.lab.robot_rate_hz)
    assert header["clock"] == "robot" and len(robot) > 10 * settings.lab.robot_rate_hz
