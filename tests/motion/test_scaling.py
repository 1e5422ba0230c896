"""One scaling around OpenSim's ScaleTool (loper_analysis.motion.scaling): the generated model's tool, the scaling
window and its pose, the mass, the scaled model's subject; on the generated model of a 1.85 m subject."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.scale_tool import measurement_pairs
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import MARKERS, SCALE_MEASUREMENTS, build_lower_body_model
from loper_analysis.motion.model_settings import ModelSettings
from loper_analysis.motion.scaling import generated_scale_tool, scaled_subject, scaling_mass_kg, scaling_pose

RATE_HZ = 128.0


@pytest.fixture(scope="module")
def models():
    """The generic model (1.73 m) and the truth (1.85 m, 80 kg) with 20 frames of its markers standing."""
    truth = build_lower_body_model(1.85, 80.0)
    t = np.arange(20) / RATE_HZ
    X = marker_positions(truth, {"pelvis_ty": np.full(t.size, 0.98)})
    return build_lower_body_model(1.73, 64.9), truth, (t, X, list(MARKERS))


def test_the_generated_models_tool_measures_each_body_by_its_marker_pair():
    tool = generated_scale_tool()
    assert measurement_pairs(tool) == {body: list(pairs) for body, pairs in SCALE_MEASUREMENTS.items()}
    assert tool.getModelScaler().getApply() and tool.getModelScaler().getPreserveMassDist()
    assert not tool.getMarkerPlacer().getApply()


def test_a_time_range_given_is_the_window_and_unsets_the_tools_own(models):
    generic, _, (t, X, labels) = models
    settings = ModelSettings(time_range_s=(t[2], t[5]))
    static = scaling_pose(generated_scale_tool(), generic, (t, X, labels), settings, static_trc="static.trc")
    assert static.window_s == (t[2], t[5])
    np.testing.assert_array_equal(static.pose.time_s, t[2:6])
    np.testing.assert_array_equal(static.pose.markers_m, X[2:6])
    assert list(static.ranges.values()) == [None]  # the model scaler's; the placer is off


def test_a_trial_shorter_than_the_static_duration_is_averaged_whole(models):
    generic, _, (t, X, labels) = models
    static = scaling_pose(generated_scale_tool(), generic, (t, X, labels), ModelSettings(), static_trc="static.trc")
    assert ModelSettings().static_duration_s > t[-1]
    assert static.window_s == (t[0], t[-1]) and static.pose.time_s.size == 20


def test_without_a_time_range_the_stillest_second_is_the_window(models):
    """The subject sways forward at 0.1 m/s for the first 1.5 s (29 mm RMS over a second), then stands still."""
    generic, _, (t, X, labels) = models
    t3 = np.arange(round(3.0 * RATE_HZ)) / RATE_HZ
    X3 = np.repeat(X[:1], t3.size, axis=0)
    X3[:, :, 0] += 0.1 * np.minimum(t3, 1.5)[:, None]
    static = scaling_pose(generated_scale_tool(), generic, (t3, X3, labels), ModelSettings(), static_trc="static.trc")
    assert static.window_s == (1.5, t3[192 + 127])  # the first second standing: 128 frames from 1.5 s
    np.testing.assert_array_equal(static.pose.markers_m, X3[192:320])
    assert max(static.pose.motion_rms_m.values()) == pytest.approx(0.0, abs=1e-12)
    # a time range given is taken as it is: the first second moves 29 mm RMS (0.1 m/s over 1 s / sqrt(12)),
    # within the limit
    first = scaling_pose(
        generated_scale_tool(), generic, (t3, X3, labels), ModelSettings(time_range_s=(0.0, 1.0)), static_trc="s"
    )
    assert first.window_s == (0.0, 1.0)
    assert max(first.pose.motion_rms_m.values()) == pytest.approx(0.1 * 1.0 / np.sqrt(12), rel=0.01)


def test_markers_in_millimetres_read_as_metres_are_refused_by_their_factors(models):
    generic, _, (t, X, labels) = models
    with pytest.raises(LoperInputError, match=r"static\.trc: scale factor\(s\) outside .*thigh_r 1\d\d\d"):
        scaling_pose(
            generated_scale_tool(),
            generic,
            (t, X * 1000.0, labels),
            ModelSettings(max_motion_rms_m=None),
            static_trc="static.trc",
        )


def test_a_measurement_marker_the_trial_lacks_is_named_with_the_setup(models):
    generic, _, (t, X, labels) = models
    keep = [i for i, name in enumerate(labels) if name != "RKNE"]
    with pytest.raises(LoperInputError, match=r"^setup\.xml: measurement marker\(s\) \['RKNE'\] are not in the static"):
        scaling_pose(
            generated_scale_tool(),
            generic,
            (t, X[:, keep], [labels[i] for i in keep]),
            ModelSettings(),
            static_trc="static.trc",
            setup_xml="setup.xml",
        )


def test_a_mass_given_is_taken_and_none_without_plates_is_refused(models):
    generic = models[0]
    assert scaling_mass_kg(generic, 80.0, None, [], (0.0, 1.0), ModelSettings()) == (80.0, "given")
    with pytest.raises(LoperInputError, match="no body mass: give mass_kg"):
        scaling_mass_kg(generic, None, None, [], (0.0, 1.0), ModelSettings())


def test_the_subjects_height_comes_given_stored_or_from_the_model(models):
    truth = models[1]
    subject = scaled_subject(truth, (80.0, "given"), ModelSettings(), None, ({}, ""), model_source="m", static_trc="s")
    assert subject == (80.0, 1.85, "mass: given; height: estimated from the scaled model", 1.85)
    stored = ({"Height": 1800.0}, "static.c3d")
    subject = scaled_subject(truth, (80.0, "plates"), ModelSettings(), None, stored, model_source="m", static_trc="s")
    assert subject == (80.0, 1.8, "mass: plates; height: PROCESSING:Height of static.c3d", 1.85)
    assert scaled_subject(truth, (80.0, "given"), ModelSettings(), 1.7, stored, model_source="m", static_trc="s")[
        1:3
    ] == (
        1.7,
        "mass: given; height: given",
    )


def test_a_scaled_model_far_from_the_height_or_without_the_bodies_is_refused(models):
    truth = models[1]
    with pytest.raises(LoperInputError, match=r"^static\.trc: the model scaled to this static trial stands 1\.85 m"):
        scaled_subject(
            truth, (80.0, "given"), ModelSettings(), 1.2, ({}, ""), model_source="m", static_trc="static.trc"
        )
    bodies = ModelSettings(segment_bodies={"thigh": ["femur_{s}"], "shank": ["tibia_{s}"], "foot": ["calcn_{s}"]})
    with pytest.raises(LoperInputError, match=r"scaled\.osim \(scaled from g\.osim\).*'femur_l' is not in the model"):
        scaled_subject(
            truth,
            (80.0, "given"),
            bodies,
            None,
            ({}, ""),
            model_source="scaled.osim (scaled from g.osim)",
            static_trc="s",
        )
