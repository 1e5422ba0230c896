"""The generic OpenSim lower-body model against our swing-leg model."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.dynamics import segment_com_positions, segment_coordinates, segment_parameters_from_anthropometry
from loper_analysis.errors import LoperInputError
from loper_analysis.model import BRACE_MARKERS, MARKERS, build_lower_body_model, segment_parameters_from_model


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "generic.osim"
    build_lower_body_model(1.73, 64.9, path)
    return path


def test_segment_table_equals_winter(model_file):
    p = segment_parameters_from_model(model_file)
    ref = segment_parameters_from_anthropometry(1.73, 64.9)
    np.testing.assert_allclose(p.packed, ref.packed, rtol=1e-12, atol=1e-14)


def test_total_mass_and_markers(model_file):
    import opensim

    m = opensim.Model(str(model_file))
    m.initSystem()
    total = sum(m.getBodySet().get(i).getMass() for i in range(m.getBodySet().getSize()))
    np.testing.assert_allclose(total, 64.9, rtol=1e-12)
    names = [m.getMarkerSet().get(i).getName() for i in range(m.getMarkerSet().getSize())]
    assert names == list(MARKERS) and set(BRACE_MARKERS) <= set(names)
    assert len(names) == 36


def test_opensim_kinematics_match_the_swing_leg_model(model_file):
    import opensim

    m = opensim.Model(str(model_file))
    state = m.initSystem()
    params = segment_parameters_from_model(model_file)
    rng = np.random.default_rng(4)
    cs = m.getCoordinateSet()
    for _ in range(10):
        tilt, tx, ty = rng.uniform(-0.2, 0.2), rng.uniform(-0.5, 0.5), rng.uniform(0.8, 1.0)
        hip, knee, ankle = rng.uniform(-0.4, 0.6), rng.uniform(0, 1.2), rng.uniform(-0.4, 0.3)
        for name, v in (("pelvis_tilt", tilt), ("pelvis_tx", tx), ("pelvis_ty", ty), ("hip_flexion_l", hip),
                        ("knee_flexion_l", knee), ("ankle_dorsiflexion_l", ankle)):
            cs.get(name).setValue(state, v, False)
        m.realizePosition(state)
        ours = segment_com_positions(segment_coordinates([hip, knee, ankle], -tilt, tx), params)
        for i, seg in enumerate(("thigh_l", "shank_l", "foot_l")):
            body = m.getBodySet().get(seg)
            com = body.findStationLocationInGround(state, body.getMassCenter())
            np.testing.assert_allclose([com.get(0), com.get(1) - ty], ours[i], atol=1e-12)


def test_bad_anthropometry():
    with pytest.raises(LoperInputError, match="height_m must lie in 1 .. 2.5 m, got 2.7"):
        build_lower_body_model(2.7, 70)
    with pytest.raises(LoperInputError, match="model file not found"):
        segment_parameters_from_model("/nonexistent/model.osim")


def test_scale_tool_recovers_a_larger_subject(model_file, tmp_path):
    from loper_analysis.kinematics import marker_positions, markers_table
    from loper_analysis.model import quiet_opensim, scale_model

    osim = quiet_opensim()
    truth_path = tmp_path / "truth.osim"
    build_lower_body_model(1.85, 80.0, truth_path)
    n = 20
    t = np.arange(n) / 128.0
    X = marker_positions(truth_path, {"pelvis_ty": np.full(n, 0.98)})
    table = markers_table(t, X * 1000.0, list(MARKERS))
    table.removeTableMetaDataKey("Units")
    for key, value in (("Units", "mm"), ("DataRate", "128"), ("CameraRate", "128")):
        table.addTableMetaDataString(key, value)
    trc = tmp_path / "static.trc"
    osim.TRCFileAdapter().write(table, str(trc))
    scaled = scale_model(model_file, trc, 80.0, tmp_path / "scaled.osim")
    p = segment_parameters_from_model(scaled)
    q = segment_parameters_from_model(truth_path)
    np.testing.assert_allclose(p.mass_kg, q.mass_kg, rtol=1e-9)
    np.testing.assert_allclose(p.cart_mass_kg, q.cart_mass_kg, rtol=1e-9)
    # uniform scaling from marker pairs whose lateral offsets do not scale: within 0.6 %
    np.testing.assert_allclose(p.length_m, q.length_m, rtol=6e-3)
    np.testing.assert_allclose(p.com_y_m, q.com_y_m, rtol=6e-3)
    np.testing.assert_allclose(p.inertia_kg_m2, q.inertia_kg_m2, rtol=1.2e-2)
    # a static trial with a gap is refused, naming marker and frame
    Xg = X.copy()
    Xg[7, list(MARKERS).index("LKNE")] = np.nan
    table = markers_table(t, Xg * 1000.0, list(MARKERS))
    table.removeTableMetaDataKey("Units")
    for key, value in (("Units", "mm"), ("DataRate", "128"), ("CameraRate", "128")):
        table.addTableMetaDataString(key, value)
    gappy = tmp_path / "gappy.trc"
    osim.TRCFileAdapter().write(table, str(gappy))
    with pytest.raises(LoperInputError, match="marker LKNE is missing at frame 7"):
        scale_model(model_file, gappy, 80.0, tmp_path / "never.osim")
    assert not (tmp_path / "never.osim").exists()
