"""The model file steps (loper_analysis.stages.model.step): scaling with OpenSim's ScaleTool and the segment tables."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import quiet_opensim, read_model, write_model
from loper_analysis.io.segment_table import read_segments
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import (
    MARKERS,
    build_lower_body_model,
    segment_parameters_from_model,
)
from loper_analysis.motion.opensim_ik import markers_table
from loper_analysis.stages.model.step import (
    ModelSettings,
    ScaleFiles,
    scale,
    segments_from_model_file,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    return write_model(build_lower_body_model(1.73, 64.9), tmp_path_factory.mktemp("model") / "generic.osim")


def _static_trc(path, t, X):
    """A static trial in mm through OpenSim's own TRC adapter."""
    osim = quiet_opensim()
    table = markers_table(t, X * 1000.0, list(MARKERS))
    table.removeTableMetaDataKey("Units")
    for key, value in (("Units", "mm"), ("DataRate", "128"), ("CameraRate", "128")):
        table.addTableMetaDataString(key, value)
    osim.TRCFileAdapter().write(table, str(path))
    return path


@pytest.fixture(scope="module")
def taller_subject():
    """The generic model of a 1.85 m, 80 kg subject and 20 frames of its markers standing."""
    truth = build_lower_body_model(1.85, 80.0)
    t = np.arange(20) / 128.0
    return truth, t, marker_positions(truth, {"pelvis_ty": np.full(t.size, 0.98)})


def test_scale_tool_recovers_a_larger_subject(model_file, taller_subject, tmp_path):
    truth, t, X = taller_subject
    trc = _static_trc(tmp_path / "static.trc", t, X)
    scale(ScaleFiles(model_file, trc, tmp_path / "scaled.osim"), 80.0)
    p = segment_parameters_from_model(read_model(tmp_path / "scaled.osim"))
    q = segment_parameters_from_model(truth)
    np.testing.assert_allclose(p.mass_kg, q.mass_kg, rtol=1e-9)
    np.testing.assert_allclose(p.cart_mass_kg, q.cart_mass_kg, rtol=1e-9)
    # uniform scaling from marker pairs whose lateral offsets do not scale: within 0.6 %
    np.testing.assert_allclose(p.length_m, q.length_m, rtol=6e-3)
    np.testing.assert_allclose(p.com_y_m, q.com_y_m, rtol=6e-3)
    np.testing.assert_allclose(p.inertia_kg_m2, q.inertia_kg_m2, rtol=1.2e-2)


def test_static_trial_with_gaps_scales_as_the_complete_one(model_file, taller_subject, tmp_path):
    _, t, X = taller_subject
    full = _static_trc(tmp_path / "full.trc", t, X)
    scale(ScaleFiles(model_file, full, tmp_path / "full.osim"), 80.0)
    Xg = X.copy()
    Xg[:10, list(MARKERS).index("LKNE")] = np.nan  # hidden while the subject settles
    Xg[7, list(MARKERS).index("RMT1")] = np.nan
    gappy = _static_trc(tmp_path / "gappy.trc", t, Xg)
    scale(ScaleFiles(model_file, gappy, tmp_path / "gappy.osim"), 80.0)
    p = segment_parameters_from_model(read_model(tmp_path / "gappy.osim"))
    q = segment_parameters_from_model(read_model(tmp_path / "full.osim"))
    np.testing.assert_allclose(p.packed, q.packed, rtol=1e-12)  # the markers stand still: their mean is their place


def test_static_trial_without_a_measurement_marker_in_its_window_is_refused(model_file, taller_subject, tmp_path):
    _, t, X = taller_subject
    Xg = X.copy()
    Xg[:, list(MARKERS).index("LKNE")] = np.nan
    gappy = _static_trc(tmp_path / "gappy.trc", t, Xg)
    with pytest.raises(
        LoperInputError,
        match=r"gappy\.trc: marker\(s\) 'LKNE' missing in every frame of the scaling "
        r"window 0\.0000 \.\. 0\.1484 s \(20 frames\)",
    ):
        scale(ScaleFiles(model_file, gappy, tmp_path / "never.osim"), 80.0)
    assert not (tmp_path / "never.osim").exists()


def test_segment_table_file_of_the_generic_model_equals_winter(model_file, tmp_path):
    out = tmp_path / "segments.tsv"
    returned = segments_from_model_file(model_file, out, ModelSettings(side="left"))
    ref = segment_parameters_from_anthropometry(1.73, 64.9)
    np.testing.assert_allclose(returned.packed, ref.packed, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(read_segments(out).packed, ref.packed, rtol=1e-9)  # 10 significant digits


def test_missing_model_file_is_named(tmp_path):
    with pytest.raises(LoperInputError, match=r"model file not found: /nonexistent/model\.osim"):
        segments_from_model_file("/nonexistent/model.osim", tmp_path / "segments.tsv")
    assert not (tmp_path / "segments.tsv").exists()
