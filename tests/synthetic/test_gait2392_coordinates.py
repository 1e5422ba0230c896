"""Our coordinates as gait2392's (loper_analysis.synthetic.gait2392_coordinates): each mapped coordinate moves the same
segment the same way in both models."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import COORDINATES, build_lower_body_model
from loper_analysis.synthetic.gait2392_coordinates import GAIT2392_COORDINATES, gait2392_coordinates
from tests.gait2392_models import gait2392_with_markers


def test_gait2392_coordinate_signs_match_our_model():
    """Each mapped coordinate moves the same segment the same way in both models (OpenSim body kinematics)."""
    ours = build_lower_body_model(1.75, 70.0)
    g = gait2392_with_markers()
    pairs = {
        "L.Knee.Lat": "LKNE",
        "L.Ankle.Lat": "LANK",
        "L.Toe.Tip": "LMT1",
        "R.Ankle.Lat": "RANK",
        "R.Toe.Tip": "RMT1",
        "L.ASIS": "LASI",
    }
    for g_name, (our_name, sign) in GAIT2392_COORDINATES.items():
        if g_name in ("pelvis_tx", "pelvis_ty"):
            continue
        g_marker = {
            "pelvis_tilt": "L.Knee.Lat",
            "hip_flexion": "L.Ankle.Lat",
            "knee_angle": "L.Ankle.Lat",
            "ankle_angle": "L.Toe.Tip",
        }[g_name.rsplit("_", 1)[0] if g_name != "pelvis_tilt" else g_name]
        if g_name.endswith("_r"):
            g_marker = "R" + g_marker[1:]
        delta = []
        for model, coordinate, value, marker in (
            (g, g_name, sign * 0.2, g_marker),
            (ours, our_name, 0.2, pairs[g_marker]),
        ):
            moved = marker_positions(model, {coordinate: value}, [marker]) - marker_positions(model, {}, [marker])
            delta.append(moved[0, 0, :2])  # sagittal plane (x forward, y up)
        cosine = delta[0] @ delta[1] / np.linalg.norm(delta[0]) / np.linalg.norm(delta[1])
        assert cosine > 0.95, (g_name, delta)
    frame = gait2392_coordinates(
        pd.DataFrame({c: [0.1 * k] for k, c in enumerate(COORDINATES)}),
        pelvis_ty_offset_m=0.5,
    )
    assert frame["knee_angle_l"][0] == pytest.approx(-0.7) and frame["pelvis_ty"][0] == pytest.approx(0.7)
