"""A response's trial inputs: the trial's name, its tables by key and its joint angles in the fit's order."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses.inputs import trial_angles, trial_name, trial_table


def _angles(n: int = 5) -> pd.DataFrame:
    """An angle table whose every column holds its own distinct values (left and right sides differ)."""
    t = np.arange(n) / 100.0
    return pd.DataFrame(
        {
            "time_s": t,
            "pelvis_x_m": 1.0 + 0.01 * np.arange(n),
            "pelvis_angle_rad": -0.1 * np.arange(n),
            "hip_left_rad": 0.1 * np.arange(n),
            "knee_left_rad": 0.2 * np.arange(n),
            "ankle_left_rad": 0.3 * np.arange(n),
            "hip_right_rad": -0.1 * np.arange(n),
            "knee_right_rad": -0.2 * np.arange(n),
            "ankle_right_rad": -0.3 * np.arange(n),
        }
    )


def test_trial_name_is_its_own_or_its_number():
    assert trial_name({"name": "pert050-1", "angles": 0}, 3, ("angles",)) == "pert050-1"
    assert trial_name({"angles": 0}, 3, ("angles",)) == "trial 3"


def test_a_trial_that_is_not_a_mapping_or_lacks_an_input_is_refused_by_name():
    with pytest.raises(LoperInputError, match=r"^S01: trial 2 must be a mapping with name, angles, strides$"):
        trial_name(["angles"], 2, ("angles", "strides"), "S01")
    with pytest.raises(LoperInputError, match=r"^pert050-1: trial input\(s\) \['force'\] missing$"):
        trial_name({"name": "pert050-1", "angles": 0}, 0, ("angles", "force"))


def test_trial_table_is_the_frame_with_its_label_and_names_a_missing_column():
    frame = pd.DataFrame({"time_s": [0.0, 0.001], "force_measured_n": [0.0, 1.5]})
    table, label = trial_table({"force": frame}, "force", "pert050-1", ("time_s", "force_measured_n"))
    assert table is frame
    assert label == "pert050-1 (force)"
    with pytest.raises(LoperInputError, match=r"^pert050-1 \(force\): column\(s\) \['force_measured_n'\] missing$"):
        trial_table({"force": frame[["time_s"]]}, "force", "pert050-1", ("time_s", "force_measured_n"))


@pytest.mark.parametrize("side, sign", [("left", 1.0), ("right", -1.0)])
def test_trial_angles_are_hip_knee_ankle_of_the_side_and_the_pelvis(side, sign):
    angles = _angles()
    t, columns, label = trial_angles({"angles": angles}, "walk-1", side)
    k = np.arange(5)
    np.testing.assert_array_equal(t, k / 100.0)
    np.testing.assert_allclose(columns["joints"], sign * np.column_stack([0.1 * k, 0.2 * k, 0.3 * k]))
    np.testing.assert_allclose(columns["pelvis_angle"], -0.1 * k)
    np.testing.assert_allclose(columns["pelvis_x"], 1.0 + 0.01 * k)
    assert label == "walk-1 (angles)"


def test_trial_angles_refuse_too_few_or_unordered_frames():
    with pytest.raises(LoperInputError, match=r"^walk-1 \(angles\): time_s must be 1-D with >= 4 frames"):
        trial_angles({"angles": _angles(3)}, "walk-1", "left")
    angles = _angles()
    angles.loc[2, "time_s"] = 0.0
    with pytest.raises(LoperInputError, match=r"^walk-1 \(angles\): time_s must increase strictly; frame 2"):
        trial_angles({"angles": angles}, "walk-1", "left")
    with pytest.raises(LoperInputError, match=r"column\(s\) \['knee_left_rad'\] missing"):
        trial_angles({"angles": angles.drop(columns="knee_left_rad")}, "walk-1", "left")
