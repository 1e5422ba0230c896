"""OpenSim's ScaleTool through a setup file (loper_analysis.io.scale_tool): the files a setup names, the setup read
with its marker set, and one run of the tool on a scaling window, on gait2392 scaled with known factors."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import write_trc
from loper_analysis.io.osim import read_marker_set, read_model
from loper_analysis.io.scale_tool import (
    measurement_markers,
    object_names,
    read_setup_tool,
    run_scale_tool,
    setup_file,
)
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.static_trial import StaticPose
from tests.gait2392_models import GENERIC, MARKER_SET, scaled_gait2392

SETUP = GENERIC.parent / "scale_setup.xml"
FACTORS = {"pelvis": 1.05, "torso": 1.02, "femur": 1.10, "tibia": 0.95, "talus": 1.08, "calcn": 1.08, "toes": 1.08}
MASS_KG = 80.0
RATE_HZ = 100.0


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """The setup with its marker set beside it, and 10 frames (100 Hz) of a subject of known proportions."""
    d = tmp_path_factory.mktemp("lab")
    shutil.copy(SETUP, d / "scale_setup.xml")
    shutil.copy(MARKER_SET, d / MARKER_SET.name)
    model = scaled_gait2392(FACTORS, MASS_KG, markers=True)
    labels = object_names(model.getMarkerSet())
    X = np.repeat(marker_positions(model, {}, labels), 10, axis=0)
    write_trc(d / "static.trc", np.arange(10) / RATE_HZ, X, labels)
    return d, np.arange(10) / RATE_HZ, X, labels


def _run(lab, pose: StaticPose, window, tool=None):
    d = lab[0]
    if tool is None:
        tool, _, _ = read_setup_tool(d / "scale_setup.xml", GENERIC, d / "static.trc")
    return run_scale_tool(
        tool,
        pose,
        window,
        {},
        mass_kg=MASS_KG,
        generic_osim=GENERIC,
        static_trc=d / "static.trc",
        out_name="scaled.osim",
        marker_set=d / MARKER_SET.name,
        setup_xml=d / "scale_setup.xml",
    )


def _pose(t, X, labels) -> StaticPose:
    return StaticPose(t, X, list(labels), {}, [], {})


def test_a_file_a_setup_names_lies_beside_the_setup_unless_absolute(tmp_path):
    setup = tmp_path / "lab" / "setup.xml"
    assert setup_file("markers.xml", setup) == (tmp_path / "lab" / "markers.xml").resolve()
    assert setup_file(" ../m.xml ", setup) == (tmp_path / "m.xml").resolve()
    assert setup_file(str(tmp_path / "abs.xml"), setup) == (tmp_path / "abs.xml").resolve()
    assert setup_file("Unassigned", setup) is None and setup_file("", setup) is None


def test_the_setups_marker_set_is_put_on_the_generic_model(lab):
    d = lab[0]
    tool, generic, marker_set = read_setup_tool(d / "scale_setup.xml", GENERIC, d / "static.trc")
    assert marker_set == (d / MARKER_SET.name).resolve()
    names, bare = object_names(generic.getMarkerSet()), read_model(GENERIC)
    assert len(names) == 39 and object_names(bare.getMarkerSet()) == []
    assert measurement_markers(tool) <= set(names)
    marker_set_file = read_marker_set(MARKER_SET)  # held: OpenSim frees a set's markers with the set
    from_file = marker_set_file.get("R.ASIS").get_location().to_numpy()
    np.testing.assert_array_equal(generic.getMarkerSet().get("R.ASIS").get_location().to_numpy(), from_file)


def test_a_setup_whose_marker_set_is_missing_is_refused_naming_where_it_looked(lab, tmp_path):
    shutil.copy(lab[0] / "scale_setup.xml", tmp_path / "setup.xml")
    with pytest.raises(LoperInputError, match=r"marker_set_file gait2392_Scale_MarkerSet\.xml not found \(looked for "):
        read_setup_tool(tmp_path / "setup.xml", GENERIC, lab[0] / "static.trc")


def test_a_run_recovers_the_known_factors_mass_and_the_placers_weights(lab):
    _, t, X, labels = lab
    run = _run(lab, _pose(t, X, labels), (0.0, 0.09))
    for body, factor in FACTORS.items():
        for name in [body] if body in ("pelvis", "torso") else [f"{body}_r", f"{body}_l"]:
            np.testing.assert_allclose(run.factors[name], (factor,) * 3, rtol=1e-9)
    bodies = run.scaled.getBodySet()
    np.testing.assert_allclose(sum(bodies.get(i).getMass() for i in range(bodies.getSize())), MASS_KG, rtol=1e-12)
    weights, coordinates = run.tasks
    assert weights["R.ASIS"] == 10.0 and weights["Sternum"] == 1.0
    assert coordinates["subtalar_angle_r"] == (1000.0, 0.0)
    assert run.window_s == (0.0, 0.09) and run.unplaced is not None
    assert run.model_osim.startswith(b"<?xml") and b"gait2392" in run.model_osim


def test_the_written_model_is_the_model_read_back(lab, tmp_path):
    _, t, X, labels = lab
    run = _run(lab, _pose(t, X, labels), (0.0, 0.09))
    (tmp_path / "scaled.osim").write_bytes(run.model_osim)
    again = read_model(tmp_path / "scaled.osim")
    for name in ("femur_r", "tibia_l", "pelvis"):
        assert again.getBodySet().get(name).getMass() == run.scaled.getBodySet().get(name).getMass()


def test_a_snapshot_is_averaged_over_its_frame_and_the_next(lab):
    _, t, X, labels = lab
    run = _run(lab, _pose(t[5:6], X[5:6], labels), (t[5], t[5]))
    assert run.window_s == (float(t[5]), float(t[5]) + 1.0 / RATE_HZ)
    np.testing.assert_allclose(run.factors["femur_r"], (1.10,) * 3, rtol=1e-9)


def test_a_tool_with_both_parts_off_writes_no_model_and_says_so(lab):
    _, t, X, labels = lab
    tool, _, _ = read_setup_tool(lab[0] / "scale_setup.xml", GENERIC, lab[0] / "static.trc")
    tool.getModelScaler().setApply(False)
    tool.getMarkerPlacer().setApply(False)
    with pytest.raises(LoperInputError, match="wrote no model .* both off"):
        _run(lab, _pose(t, X, labels), (0.0, 0.09), tool)


def test_the_static_trial_must_be_a_trc(lab, tmp_path):
    static = Path(tmp_path / "static.c3d")
    static.write_bytes(b"")
    with pytest.raises(LoperInputError, match=r"static\.c3d: ScaleTool reads a static trial as \.trc, got '\.c3d'"):
        read_setup_tool(lab[0] / "scale_setup.xml", GENERIC, static)
