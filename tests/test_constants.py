"""constants.py: the column names built from the shared names, and the Z-up lab's constants against the rotation
they stand for."""

from __future__ import annotations

import numpy as np

from loper_analysis.constants import (
    LAB_TO_MODEL_ROTATION_DEG,
    LAB_Z_UP,
    PARAMETER_UNITS,
    PARAMETERS,
    angle_column,
    parameter_column,
)
from loper_analysis.motion.markers import lab_up, rotate_markers


def test_angle_columns():
    assert angle_column("hip", "left") == "hip_left_rad"
    assert angle_column("ankle", "right") == "ankle_right_rad"


def test_parameter_columns_carry_the_unit_of_their_kind():
    assert parameter_column("K") == "K_nm_per_rad"
    assert parameter_column("D") == "D_nms_per_rad"
    assert parameter_column("D", "ci95_low") == "D_ci95_low_nms_per_rad"
    assert parameter_column("K", "true") == "K_true_nm_per_rad"
    assert PARAMETER_UNITS == {
        "K_hip": "N·m/rad",
        "D_hip": "N·m·s/rad",
        "K_knee": "N·m/rad",
        "D_knee": "N·m·s/rad",
        "K_ankle": "N·m/rad",
        "D_ankle": "N·m·s/rad",
    }
    assert list(PARAMETER_UNITS) == list(PARAMETERS)


def test_the_z_up_labs_rotation_takes_its_up_to_the_models():
    np.testing.assert_allclose(lab_up(LAB_TO_MODEL_ROTATION_DEG), LAB_Z_UP, atol=1e-15)
    np.testing.assert_allclose(rotate_markers(np.array(LAB_Z_UP), LAB_TO_MODEL_ROTATION_DEG), [0, 1, 0], atol=1e-15)
    # lab forward (+X) stays the model's forward, lab left (+Y) becomes the model's -Z (Z points right)
    np.testing.assert_allclose(
        rotate_markers(np.eye(3)[:2], LAB_TO_MODEL_ROTATION_DEG), [[1, 0, 0], [0, 0, -1]], atol=1e-15
    )
