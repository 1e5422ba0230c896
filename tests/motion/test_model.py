"""The generic OpenSim lower-body model (loper_analysis.motion.model) against our swing-leg model."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.model import (
    BRACE_MARKERS,
    MARKERS,
    build_lower_body_model,
    segment_parameters_from_model,
)
from loper_analysis.swing_leg.dynamics import segment_coordinates, segment_parameters_from_anthropometry
from tests.swing_leg.reference_dynamics import segment_com_positions


@pytest.fixture(scope="module")
def model():
    return build_lower_body_model(1.73, 64.9)


def test_segment_table_equals_winter(model):
    p = segment_parameters_from_model(model)
    ref = segment_parameters_from_anthropometry(1.73, 64.9)
    np.testing.assert_allclose(p.packed, ref.packed, rtol=1e-12, atol=1e-14)


def test_total_mass_and_markers(model):
    model.initSystem()
    total = sum(model.getBodySet().get(i).getMass() for i in range(model.getBodySet().getSize()))
    np.testing.assert_allclose(total, 64.9, rtol=1e-12)
    names = [model.getMarkerSet().get(i).getName() for i in range(model.getMarkerSet().getSize())]
    assert names == list(MARKERS) and set(BRACE_MARKERS) <= set(names)
    assert len(names) == 36


def test_opensim_kinematics_match_the_swing_leg_model(model):
    state = model.initSystem()
    params = segment_parameters_from_model(model)
    rng = np.random.default_rng(4)
    cs = model.getCoordinateSet()
    for _ in range(10):
        tilt, tx, ty = rng.uniform(-0.2, 0.2), rng.uniform(-0.5, 0.5), rng.uniform(0.8, 1.0)
        hip, knee, ankle = rng.uniform(-0.4, 0.6), rng.uniform(0, 1.2), rng.uniform(-0.4, 0.3)
        for name, v in (
            ("pelvis_tilt", tilt),
            ("pelvis_tx", tx),
            ("pelvis_ty", ty),
            ("hip_flexion_l", hip),
            ("knee_flexion_l", knee),
            ("ankle_dorsiflexion_l", ankle),
        ):
            cs.get(name).setValue(state, v, False)
        model.realizePosition(state)
        ours = segment_com_positions(segment_coordinates([hip, knee, ankle], -tilt, tx), params)
        for i, seg in enumerate(("thigh_l", "shank_l", "foot_l")):
            body = model.getBodySet().get(seg)
            com = body.findStationLocationInGround(state, body.getMassCenter())
            np.testing.assert_allclose([com.get(0), com.get(1) - ty], ours[i], atol=1e-12)


def test_bad_anthropometry():
    with pytest.raises(LoperInputError, match="height_m must lie in 1 .. 2.5 m, got 2.7"):
        build_lower_body_model(2.7, 70)
