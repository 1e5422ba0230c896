"""The study's design: trial names, onsets and conditions, against the config and by hand."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from loper_analysis.study_design import DEVICE_TESTS, StudyDesign, perturbation_trial_name

ROOT = Path(__file__).resolve().parents[1]


def test_the_library_default_is_the_config_default():
    config = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    assert StudyDesign() == stage_settings(config, "study").design


def test_trials_of_the_default_design():
    d = StudyDesign()
    assert d.perturbation_trials() == ["pert050-1", "pert050-2", "pert175-1", "pert175-2", "pert300-1", "pert300-2"]
    assert d.perturbation_trials(175) == ["pert175-1", "pert175-2"]
    assert d.walking_trials() == ["walk-nodevice", "walk-device", *d.perturbation_trials()]
    assert d.trials() == ["static", *d.walking_trials(), "device-frf", "device-steps"]
    assert len(d.trials()) == 1 + 2 + 3 * 2 + len(DEVICE_TESTS) == 11


def test_a_trial_name_gives_its_onset_only_within_the_design():
    d = StudyDesign(perturbation_onsets_ms=(50, 5), perturbation_repeats=3)
    assert [d.onset_ms(t) for t in ("pert050-1", "pert050-3", "pert005-2", "pert050-4", "pert100-1", "static")] == [
        50,
        50,
        5,
        None,
        None,
        None,
    ]
    assert d.onsets_of(["pert005-1", "walk-device", "pert050-2", "pert005-3"]) == [50, 5]  # the design's order


@pytest.mark.parametrize(
    ("trial", "condition", "kind", "robot"),
    [
        ("static", "static", "static", False),
        ("walk-nodevice", "no_device", "walking", False),
        ("walk-device", "device", "walking", True),
        ("pert300-2", "perturbation", "walking", True),
        ("device-frf", "device_test", "walking", True),
    ],
)
def test_conditions(trial, condition, kind, robot):
    d = StudyDesign()
    assert (d.condition(trial), d.kind(trial), d.with_robot(trial)) == (condition, kind, robot)


def test_names_outside_the_design_are_refused_by_name():
    with pytest.raises(
        LoperInputError,
        match=r"trial 'pert100-1' is no trial of the design \(static, walk-nodevice, "
        r"walk-device, pert050-1, .*, device-steps\)",
    ):
        StudyDesign().condition("pert100-1")
    assert perturbation_trial_name(7, 12) == "pert007-12"
    with pytest.raises(LoperInputError, match=r"onset 1000 ms must lie in 0 \.\. 999"):
        perturbation_trial_name(1000, 1)
