"""OpenSim's solver over a trial (loper_analysis.motion.opensim_ik): known angles of the generated model.

The comparison with OpenSim's ``InverseKinematicsTool`` and Rajagopal2016's locked and coupled coordinates
run for both solvers in ``tests/motion/test_ik.py``.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import MARKERS, build_lower_body_model
from loper_analysis.motion.opensim_ik import opensim_solution


def test_known_angles_come_back_in_coordinate_set_order():
    model = build_lower_body_model(1.73, 64.9)
    t = np.arange(40) / 128.0
    truth = {
        "pelvis_ty": 0.93 + 0.01 * np.sin(4 * t),
        "hip_flexion_l": 0.1 + 0.3 * np.sin(4 * t),
        "knee_flexion_l": 0.6 + 0.5 * np.sin(4 * t + 1),
        "ankle_dorsiflexion_r": -0.1 * np.sin(4 * t + 2),
    }
    X = marker_positions(model, truth)
    frames = np.arange(5, 40)
    Q, E, in_use = opensim_solution(
        model,
        t,
        X,
        list(MARKERS),
        dict.fromkeys(MARKERS, 1.0),
        coordinate_tasks={},
        frames=frames,
        accuracy=1e-8,
        source="synthetic",
    )
    cs = model.getCoordinateSet()
    names = [cs.get(i).getName() for i in range(cs.getSize())]
    assert np.isnan(Q[:5]).all() and np.isnan(E[:5]).all()  # frames not asked for
    for name, values in truth.items():
        np.testing.assert_allclose(Q[5:, names.index(name)], values[5:], atol=1e-6, err_msg=name)  # measured 2e-7
    assert sorted(in_use) == sorted(MARKERS) and E[5:].max() < 1e-6
