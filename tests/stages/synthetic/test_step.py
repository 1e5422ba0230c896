"""The simulated lab's file steps (stages/synthetic/step.py): the session's files by trial, and a short session written
to disk."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.robot_log import read_robot_log
from loper_analysis.stages.settings import stage_settings
from loper_analysis.stages.synthetic.step import LabSessionFiles, lab_session, truth
from loper_analysis.study_design import StudyDesign
from loper_analysis.synthetic.subjects import subject_anthropometry

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


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
    config["study"].update(perturbation_onsets_ms=[50], perturbation_repeats=1)
    config["synthetic"]["walking_duration_s"] = 10.0
    settings = stage_settings(config, "synthetic")
    row = subject_anthropometry({"subject": "S09", "source": "synthetic"}, settings.seed)
    truth(tmp_path / "truth.yaml", row, settings.truth, settings.seed)
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
        "synthetic_lab.generated.sha256",  # the checksums of the files the lab wrote
        "truth.yaml",
        "walk-device.c3d",
        "walk-device.loper.tsv",
        "walk-nodevice.c3d",
    ]
    walking = read_c3d(tmp_path / "pert050-1.c3d")
    assert walking.markers_m.shape[0] == round(10.0 * settings.lab.marker_rate_hz)
    static_frames = round(config["synthetic"]["static_duration_s"] * 128.0)
    assert read_c3d(tmp_path / "static.c3d").markers_m.shape[0] == static_frames
    robot, header = read_robot_log(tmp_path / "pert050-1.loper.tsv", settings.lab.robot_rate_hz)
    assert header["clock"] == "robot" and len(robot) > 10 * settings.lab.robot_rate_hz
