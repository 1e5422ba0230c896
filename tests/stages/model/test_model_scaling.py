"""Scaling with a lab's own ScaleTool setup (steps.model.scale_with_setup) on gait2392.

The static trial is made here: gait2392 with its scale markers is scaled
with known factors (OpenSim's Model.scale) and its markers' ground
positions in the default pose are written as a TRC. The lab setup
(``examples/gait2392/scale_setup.xml``) must recover the factors, and our
step must give the same model as OpenSim's own ``ScaleTool(setup).run()``.
"""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.opensim_tables import read_markers, write_trc
from loper_analysis.io.osim import quiet_opensim, read_model
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.segments import segments_from_model
from loper_analysis.stages.model.step import ModelSettings, ScaleFiles, scale_with_setup
from tests.gait2392_models import scaled_gait2392

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT / "examples" / "gait2392"
GENERIC = DATA / "gait2392_simbody.osim"
MARKER_SET = DATA / "gait2392_Scale_MarkerSet.xml"
SETUP = ROOT / "examples" / "gait2392" / "scale_setup.xml"
FACTORS = {"pelvis": 1.05, "torso": 1.02, "femur": 1.10, "tibia": 0.95, "talus": 1.08, "calcn": 1.08, "toes": 1.08}
MASS_KG = 80.0
GENERIC_MASS_KG = 75.1646


def _files(setup, static, out, **optional) -> ScaleFiles:
    """The files of scaling gait2392 with the setup ``setup`` to the static trial ``static``, into ``out``."""
    return ScaleFiles(GENERIC, static, out, setup_xml=setup, **optional)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A lab folder: the setup, its marker set beside it, and a static trial of a subject of known proportions."""
    d = tmp_path_factory.mktemp("lab")
    shutil.copy(SETUP, d / "scale_setup.xml")
    shutil.copy(MARKER_SET, d / MARKER_SET.name)
    model = scaled_gait2392(FACTORS, MASS_KG, markers=True)
    markers = model.getMarkerSet()
    labels = [markers.get(i).getName() for i in range(markers.getSize())]
    X = np.repeat(marker_positions(model, {}, labels), 10, axis=0)
    write_trc(d / "static.trc", np.arange(10) / 100.0, X, labels)
    return d


@pytest.fixture(scope="module")
def scaled(lab):
    out = lab / "out" / "scaled.osim"
    scale_with_setup(_files(lab / "scale_setup.xml", lab / "static.trc", out), MASS_KG)
    return out


def test_lab_setup_recovers_the_known_factors(scaled):
    model, generic = read_model(scaled), read_model(GENERIC)
    p, g = segments_from_model(model, "l"), segments_from_model(generic, "l")
    ratios = np.array(p.length_m) / np.array(g.length_m)
    np.testing.assert_allclose(ratios, (1.10, 0.95, 1.08), rtol=1e-9)
    for body in ("pelvis", "femur_r", "tibia_l", "calcn_r", "toes_l", "torso"):
        np.testing.assert_allclose(
            model.getBodySet().get(body).getMass(),
            generic.getBodySet().get(body).getMass() * MASS_KG / GENERIC_MASS_KG,
            rtol=1e-12,
        )
    hip = model.getJointSet().get("hip_r").getParentFrame().findTransformInBaseFrame().p().to_numpy()
    np.testing.assert_allclose(hip, 1.05 * np.array([-0.0707, -0.0661, 0.0835]), rtol=1e-9)


def _peer_setup(lab: Path, d: Path) -> Path:
    """The lab setup filled in by hand (files beside it) for OpenSim's own ScaleTool."""
    for f in (GENERIC, lab / MARKER_SET.name, lab / "static.trc"):
        shutil.copy(f, d / f.name)
    text = (lab / "scale_setup.xml").read_text()
    text = text.replace("<mass>75</mass>", f"<mass>{MASS_KG}</mass>")
    text = text.replace("<model_file>gait2392_simbody.osim</model_file>", f"<model_file>{GENERIC.name}</model_file>")
    text = re.sub(r"<time_range>[^<]*</time_range>", "<time_range> 0 0.09</time_range>", text)
    text = text.replace(
        "<output_model_file>scaled.osim</output_model_file>", "<output_model_file>peer.osim</output_model_file>"
    )
    (d / "setup.xml").write_text(text)
    return d / "setup.xml"


def test_step_equals_opensims_own_scale_tool(lab, scaled, tmp_path):
    osim = quiet_opensim()
    assert osim.ScaleTool(str(_peer_setup(lab, tmp_path))).run()
    ours, peer = read_model(scaled), read_model(tmp_path / "peer.osim")
    s1, s2 = ours.initSystem(), peer.initSystem()
    bodies = peer.getBodySet()
    assert ours.getBodySet().getSize() == bodies.getSize() == 12
    for i in range(bodies.getSize()):
        b2 = bodies.get(i)
        b1 = ours.getBodySet().get(b2.getName())
        np.testing.assert_allclose(b1.getMass(), b2.getMass(), rtol=1e-9)
        np.testing.assert_allclose(b1.getMassCenter().to_numpy(), b2.getMassCenter().to_numpy(), rtol=1e-9, atol=1e-12)
        for part in ("getMoments", "getProducts"):
            np.testing.assert_allclose(
                getattr(b1.getInertia(), part)().to_numpy(),
                getattr(b2.getInertia(), part)().to_numpy(),
                rtol=1e-9,
                atol=1e-12,
            )
    joints = peer.getJointSet()
    for i in range(joints.getSize()):
        j2 = joints.get(i)
        j1 = ours.getJointSet().get(j2.getName())
        for frame in ("getParentFrame", "getChildFrame"):
            np.testing.assert_allclose(
                getattr(j1, frame)().findTransformInBaseFrame().p().to_numpy(),
                getattr(j2, frame)().findTransformInBaseFrame().p().to_numpy(),
                atol=1e-9,
            )
            np.testing.assert_allclose(
                getattr(j1, frame)().getPositionInGround(s1).to_numpy(),
                getattr(j2, frame)().getPositionInGround(s2).to_numpy(),
                atol=1e-9,
            )
    m1, m2 = ours.getMarkerSet(), peer.getMarkerSet()
    assert m1.getSize() == m2.getSize() == 39
    for i in range(m2.getSize()):
        np.testing.assert_allclose(
            m1.get(m2.get(i).getName()).get_location().to_numpy(), m2.get(i).get_location().to_numpy(), atol=1e-9
        )
    np.testing.assert_allclose(segments_from_model(ours, "l").packed, segments_from_model(peer, "l").packed, rtol=1e-9)


def test_not_a_scale_setup_is_refused(lab, tmp_path):
    with pytest.raises(
        LoperInputError,
        match=r"gait2392_Scale_MarkerSet\.xml: not an OpenSim ScaleTool setup "
        r"\(its <OpenSimDocument> element holds no <ScaleTool>\)",
    ):
        scale_with_setup(_files(MARKER_SET, lab / "static.trc", tmp_path / "never.osim"), MASS_KG)
    assert not (tmp_path / "never.osim").exists()


def test_markers_the_static_trial_lacks_are_listed(lab, tmp_path):
    t, X, labels = read_markers(lab / "static.trc")
    keep = [i for i, name in enumerate(labels) if name not in ("R.Knee.Lat", "L.Heel")]
    write_trc(tmp_path / "short.trc", t, X[:, keep], [labels[i] for i in keep])
    with pytest.raises(
        LoperInputError,
        match=r"scale_setup\.xml: measurement marker\(s\) \['L\.Heel', 'R\.Knee\.Lat'\] "
        r"are not in the static trial .*short\.trc",
    ):
        scale_with_setup(_files(lab / "scale_setup.xml", tmp_path / "short.trc", tmp_path / "never.osim"), MASS_KG)
    assert not (tmp_path / "never.osim").exists()


def test_markers_the_model_lacks_are_listed(lab, tmp_path):
    shutil.copy(lab / MARKER_SET.name, tmp_path / MARKER_SET.name)
    text = (lab / "scale_setup.xml").read_text().replace("L.Thigh.Upper L.Knee.Lat", "L.Thigh.Upper L.Epicondyle")
    (tmp_path / "setup.xml").write_text(text)
    with pytest.raises(
        LoperInputError,
        match=r"setup\.xml: measurement marker\(s\) \['L\.Epicondyle'\] are not on the "
        r"model .*gait2392_simbody\.osim with marker set .*gait2392_Scale_MarkerSet",
    ):
        scale_with_setup(_files(tmp_path / "setup.xml", lab / "static.trc", tmp_path / "never.osim"), MASS_KG)
    assert not (tmp_path / "never.osim").exists()


def test_markers_missing_in_some_frames_are_averaged_over_the_others(lab, scaled, tmp_path):
    # as labs record them: knee condyles hidden for the first frames, an ankle marker lost for one frame
    t, X, labels = read_markers(lab / "static.trc")
    X[:3, labels.index("R.Knee.Lat")] = np.nan
    X[:4, labels.index("L.Knee.Lat")] = np.nan
    X[6, labels.index("R.Ankle.Lat")] = np.nan
    write_trc(tmp_path / "gappy.trc", t, X, labels)
    scale_with_setup(_files(lab / "scale_setup.xml", tmp_path / "gappy.trc", tmp_path / "gappy.osim"), MASS_KG)
    ours, full = read_model(tmp_path / "gappy.osim"), read_model(scaled)
    # the markers stand still, so their mean over the present frames is their position: the same model
    np.testing.assert_allclose(segments_from_model(ours, "r").packed, segments_from_model(full, "r").packed, rtol=1e-12)
    m1, m2 = ours.getMarkerSet(), full.getMarkerSet()
    for i in range(m2.getSize()):
        np.testing.assert_allclose(
            m1.get(m2.get(i).getName()).get_location().to_numpy(), m2.get(i).get_location().to_numpy(), atol=1e-12
        )


def test_marker_absent_from_the_whole_window_is_refused_naming_label_file_and_window(lab, tmp_path):
    t, X, labels = read_markers(lab / "static.trc")
    X[:6, labels.index("R.Ankle.Lat")] = np.nan
    write_trc(tmp_path / "gappy.trc", t, X, labels)
    with pytest.raises(
        LoperInputError,
        match=r"gappy\.trc: marker\(s\) 'RANK' \(model marker R\.Ankle\.Lat\) missing "
        r"in every frame of the scaling window 0\.0000 \.\. 0\.0500 s \(6 frames\)",
    ):
        scale_with_setup(
            _files(lab / "scale_setup.xml", tmp_path / "gappy.trc", tmp_path / "never.osim"),
            MASS_KG,
            ModelSettings(time_range_s=(0.0, 0.05)),
            lab_labels={"R.Ankle.Lat": "RANK"},
        )
    assert not (tmp_path / "never.osim").exists()
    # a window in which it is present scales: frames 6 .. 9
    scale_with_setup(
        _files(lab / "scale_setup.xml", tmp_path / "gappy.trc", tmp_path / "late.osim"),
        MASS_KG,
        ModelSettings(time_range_s=(0.06, 0.09)),
    )
    p = segments_from_model(read_model(tmp_path / "late.osim"), "r")
    np.testing.assert_allclose(p.length_m[1] / 0.43, 0.95, rtol=1e-9)


def test_the_setups_time_range_is_honoured(lab, tmp_path):
    # a lab's setup that averages 0 .. 0.05 s: the frames after it do not count
    shutil.copy(lab / MARKER_SET.name, tmp_path / MARKER_SET.name)
    (tmp_path / "setup.xml").write_text(
        (lab / "scale_setup.xml")
        .read_text()
        .replace("<time_range> -1 -1</time_range>", "<time_range> 0 0.05</time_range>")
    )
    t, X, labels = read_markers(lab / "static.trc")
    X[7:, labels.index("R.Ankle.Lat")] += 0.5  # the subject moves after the window: no effect
    write_trc(tmp_path / "moved.trc", t, X, labels)
    scale_with_setup(_files(tmp_path / "setup.xml", tmp_path / "moved.trc", tmp_path / "early.osim"), MASS_KG)
    p = segments_from_model(read_model(tmp_path / "early.osim"), "r")
    np.testing.assert_allclose(p.length_m[1] / 0.43, 0.95, rtol=1e-9)
    # a trial starting later holds no frame of it and is refused with both spans
    write_trc(tmp_path / "late.trc", t + 7.8125, X, labels)
    with pytest.raises(
        LoperInputError,
        match=r"late\.trc: time_range of .*setup\.xml 0 \.\. 0\.05 s holds no frame "
        r"of the static trial \(7\.8125 \.\. 7\.9025 s, the file's clock\)",
    ):
        scale_with_setup(_files(tmp_path / "setup.xml", tmp_path / "late.trc", tmp_path / "never.osim"), MASS_KG)
    assert not (tmp_path / "never.osim").exists()


def test_scaled_model_without_the_configured_bodies_is_refused(lab, tmp_path):
    bodies = {"thigh": ["thigh_{s}"], "shank": ["shank_{s}"], "foot": ["foot_{s}"]}
    with pytest.raises(
        LoperInputError,
        match=r"never\.osim \(scaled from .*gait2392_simbody\.osim\): "
        r"model\.segment_bodies: thigh body 'thigh_l' is not in the model",
    ):
        scale_with_setup(
            _files(lab / "scale_setup.xml", lab / "static.trc", tmp_path / "never.osim"),
            MASS_KG,
            ModelSettings(segment_bodies=bodies),
        )
    assert not (tmp_path / "never.osim").exists()
    assert not list(tmp_path.iterdir())


def test_scale_report_gives_the_known_factors_and_no_marker_error(lab, tmp_path):
    scale_with_setup(
        _files(
            lab / "scale_setup.xml", lab / "static.trc", tmp_path / "scaled.osim", report_out=tmp_path / "scale.tsv"
        ),
        MASS_KG,
        lab_labels={"R.ASIS": "Subject:RASI"},
    )
    report = pd.read_csv(tmp_path / "scale.tsv", sep="\t")
    bodies = report[report.kind == "body"].set_index("name")
    for body, factor in FACTORS.items():
        for side in [""] if body in ("pelvis", "torso") else ["_r", "_l"]:
            np.testing.assert_allclose(
                bodies.loc[body + side, ["scale_factor_x", "scale_factor_y", "scale_factor_z"]], factor, rtol=1e-9
            )
    markers = report[report.kind == "marker"].set_index("name")
    assert markers.loc["R.ASIS", "label"] == "Subject:RASI" and markers.loc["L.ASIS", "label"] == "L.ASIS"
    # the static trial is the known model's markers: after scaling and placement they coincide
    assert markers["marker_error_m"].max() < 1e-5
    subject = report[report.kind == "subject"].iloc[0]
    assert subject.mass_kg == MASS_KG and subject.source == "mass: given; height: estimated from the scaled model"
