"""Which coordinates a marker subset determines (loper_analysis.motion.ik_determinacy), on the generated model."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.ik_determinacy import (
    model_tree,
    require_markers_beyond_root,
    undetermined_coordinates,
)
from loper_analysis.motion.model import COORDINATES, build_lower_body_model


@pytest.fixture(scope="module")
def tree():
    return model_tree(build_lower_body_model(1.75, 70.0))


def test_tree_of_the_generated_model(tree):
    assert tree.coordinates == COORDINATES and tree.root_bodies == {"pelvis"} and tree.fixed == frozenset()
    assert tree.moved_bodies["knee_flexion_l"] == {"shank_l", "foot_l"}
    assert tree.moved_bodies["pelvis_tx"] == {"pelvis", *(f"{s}_{x}" for s in ("thigh", "shank", "foot") for x in "rl")}
    assert tree.marker_bodies["LKNE"] == "thigh_l" and tree.marker_bodies["LANK"] == "shank_l"


def test_undetermined_frames_of_a_marker_subset(tree):
    labels = ["RASI", "LASI", "RPSI", "LKNE", "LTIB_AS"]
    X = np.ones((10, len(labels), 3))
    X[5:, 4] = np.nan  # the shank marker leaves after frame 4
    free = undetermined_coordinates(tree, X, labels, {"ankle_dorsiflexion_r": (1.0, None)})
    n = dict(zip(tree.coordinates, free.sum(axis=0).tolist()))
    assert n == {
        "pelvis_tilt": 0,
        "pelvis_tx": 0,
        "pelvis_ty": 0,
        "hip_flexion_r": 10,
        "knee_flexion_r": 10,
        "ankle_dorsiflexion_r": 0,
        "hip_flexion_l": 0,
        "knee_flexion_l": 5,
        "ankle_dorsiflexion_l": 10,
    }
    assert (
        free[5:, COORDINATES.index("knee_flexion_l")].all() and not free[:5, COORDINATES.index("knee_flexion_l")].any()
    )


def test_pelvis_only_markers_are_refused_and_one_limb_marker_passes(tree):
    X = np.ones((3, 4, 3))
    with pytest.raises(
        LoperInputError,
        match=r"walk\.trc: the 3 weighted marker\(s\) present \(RASI, LASI, RPSI\) "
        r"all sit on pelvis",
    ):
        require_markers_beyond_root(tree, X[:, :3], ["RASI", "LASI", "RPSI"], "walk.trc")
    X[:, 3] = np.nan  # a limb marker missing in every frame does not count
    with pytest.raises(LoperInputError, match="all sit on pelvis"):
        require_markers_beyond_root(tree, X, ["RASI", "LASI", "RPSI", "LHEE"], "walk.trc")
    X[1, 3] = 0.5
    require_markers_beyond_root(tree, X, ["RASI", "LASI", "RPSI", "LHEE"], "walk.trc")
