"""The subject calibration's virtual markers on a template's model: which a static trial yields, where they sit on
gait2392, which template a marker set is."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.io.marker_templates import template_file
from loper_analysis.io.osim import quiet_opensim, read_model
from loper_analysis.motion.centre_markers import calibration_centres, joint_centre_places, marker_set_centres
from loper_analysis.stages.templates import read_templates

PIG_LABELS = [f"{s}{c}" for s in "LR" for c in ("ASI", "PSI", "THI", "KNE", "TIB", "ANK", "HEE", "TOE")]
CENTRES = ["LHJC", "RHJC", "LKJC", "RKJC", "LAJC", "RAJC", "PELVIS_FRONT", "PELVIS_BACK", "LKNEE_LAT", "LKNEE_MED",
           "LFOOT_UP", "LFOOT_DOWN", "RKNEE_LAT", "RKNEE_MED", "RFOOT_UP", "RFOOT_DOWN"]  # fmt: skip


@pytest.fixture(scope="module")
def pig():
    return read_templates()["plugin_gait"]


def test_a_static_trial_yields_the_centres_only_with_every_landmark(pig):
    assert calibration_centres(pig.joint_centres, PIG_LABELS) == CENTRES
    sacrum = [m for m in PIG_LABELS if not m.endswith("PSI")] + ["SACR"]
    assert calibration_centres(pig.joint_centres, sacrum) == CENTRES  # the sacrum for the posterior spines
    for lacking in ("RPSI", "LANK", "RTOE"):
        assert calibration_centres(pig.joint_centres, [m for m in PIG_LABELS if m != lacking]) == [], lacking
    assert calibration_centres(read_templates()["isb"].joint_centres, PIG_LABELS) == []  # a template without centres


def test_the_centres_sit_at_the_models_own_joints_in_the_default_pose(pig):
    """Each centre is where OpenSim puts the child body's origin, in the parent's frame: the hip's place as the
    model file writes it, the knee's at zero flexion (its translation functions), the ankle's."""
    osim = quiet_opensim()
    model = read_model(template_file(pig.model))
    places = joint_centre_places(pig.joint_centres, pig.locations(), model, "template plugin_gait")
    assert set(places) == set(CENTRES)
    state = model.initSystem()
    for name, (parent, child) in pig.joint_centres.centres.items():
        body, location = places[name]
        assert body == parent
        ground = model.getBodySet().get(child).getPositionInGround(state).to_numpy()
        back = model.getBodySet().get(parent).findStationLocationInGround(state, osim.Vec3(*location))
        np.testing.assert_allclose(back.to_numpy(), ground, atol=1e-12)
    np.testing.assert_allclose(places["LHJC"][1], (-0.0707, -0.0661, -0.0835), atol=1e-12)
    assert places["RFOOT_UP"] == ("talus_r", pytest.approx((0.0, 0.1, 0.0), abs=1e-12))
    assert places["RFOOT_DOWN"] == ("talus_r", pytest.approx((0.0, -0.1, 0.0), abs=1e-12))
    knee = np.array(places["LKJC"][1])  # the knee's axis: gait2392's femur z, lateral to the left for the left knee
    np.testing.assert_allclose(places["LKNEE_LAT"][1], knee + [0.0, 0.0, -0.1], atol=1e-12)
    np.testing.assert_allclose(places["LKNEE_MED"][1], knee + [0.0, 0.0, 0.1], atol=1e-12)


def test_a_marker_set_is_told_by_its_centres(pig):
    templates = list(read_templates().values())
    assert (
        marker_set_centres([t.joint_centres for t in templates], [*PIG_LABELS, *CENTRES]) == pig.joint_centres
    )  # read twice: equal
    assert (
        marker_set_centres([t.joint_centres for t in templates], PIG_LABELS) is None
    )  # written before the centres: its places are fitted
    assert (
        marker_set_centres([t.joint_centres for t in templates], ["R.ASIS", "L.ASIS", "R.Heel"]) is None
    )  # a lab's own marker set
