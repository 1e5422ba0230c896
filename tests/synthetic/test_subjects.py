"""Synthetic subjects: anthropometrics drawn per subject, the true impedance, and the truth step's file."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.io.truth import read_truth
from loper_analysis.stages.synthetic.step import truth as truth_step
from loper_analysis.synthetic.subjects import ImpedanceTruth, subject_anthropometry, true_impedance

K = {50: [55, 3, 8], 175: [38, 0.5, 8]}
D = {50: [3.5, 0.1, 0.3], 175: [2.2, 0.04, 0.3]}


@pytest.fixture(scope="module")
def anthropometry():
    return subject_anthropometry({"subject": "S07"}, 2024)


@pytest.fixture(scope="module")
def truth():
    return true_impedance("S07", 2024, K, D, 0.15)


def test_missing_anthropometrics_are_drawn_seeded_by_subject(anthropometry):
    a = anthropometry
    assert a == subject_anthropometry({"subject": "S07"}, 2024)  # seeded by subject
    assert 1.45 <= a["height_m"] <= 2.01 and 40.7 <= a["mass_kg"] <= 89.1 and a["sex"] in ("male", "female")


def test_given_anthropometrics_are_kept():
    given = subject_anthropometry({"subject": "S07", "height_m": 1.9, "mass_kg": 80.0, "sex": "female"}, 2024)
    assert (given["height_m"], given["mass_kg"], given["sex"]) == (1.9, 80.0, "female")


def test_implausible_anthropometrics_are_refused_naming_subject_and_value():
    with pytest.raises(LoperInputError, match="subject S08: mass_kg = -3.0"):
        subject_anthropometry({"subject": "S08", "mass_kg": -3.0}, 1)
    with pytest.raises(LoperInputError, match="height_m = 2.7"):
        subject_anthropometry({"subject": "S08", "height_m": 2.7}, 1)


def test_true_impedance_scatters_about_the_group_values(truth):
    ratios = [truth[o][j]["K"] / K[o][i] for o in K for i, j in enumerate(JOINTS)]
    assert 0.6 < min(ratios) and max(ratios) < 1.6 and np.std(ratios) > 0.01


def test_truth_step_writes_the_true_impedance(tmp_path, anthropometry, truth):
    path = tmp_path / "S07" / "truth.yaml"
    returned = truth_step(path, anthropometry, ImpedanceTruth(K, D, 0.15, (0.0, 200.0), (0.0, 10.0)), 2024)
    assert returned == truth
    assert read_truth(path) == truth


def test_true_impedance_outside_the_bounds_is_refused():
    with pytest.raises(LoperInputError, match=r"onset 50 ms, hip: true K = 2.*outside the identification bounds"):
        true_impedance("S07", 2024, {50: [250, 3, 8]}, {50: [3.5, 0.1, 0.3]}, 0.0)
