"""Points of a C3D file that are not markers: a clinical lab's Plug-in Gait outputs, kept apart from its markers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_points import MARKER, SEGMENT_POINT, UNLABELLED, point_kinds

QCMAS = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "QCMAS"
#: The markers of the lab's files (README of tests/data/c3d-parser): 21 in the walk, 4 medial ones more in the static.
WALK_MARKERS = [
    "C7", "T10", "CLAV", "STRN", "RBAK", "LASI", "RASI", "LPSI", "RPSI", "LTHI", "LKNE", "LTIB", "LANK", "LHEE",
    "LTOE", "RTHI", "RKNE", "RTIB", "RANK", "RHEE", "RTOE",
]  # fmt: skip


def test_the_clinical_files_hold_25_and_21_markers_and_their_model_outputs_apart():
    static = read_c3d(QCMAS / "static.c3d")
    walk = read_c3d(QCMAS / "walk-nodevice.c3d")
    assert static.marker_labels == WALK_MARKERS + ["LMKNE", "RMKNE", "LMMAL", "RMMAL"]
    assert walk.marker_labels == WALK_MARKERS
    assert len(static.marker_labels) + len(static.output_labels) == 179
    assert len(walk.marker_labels) + len(walk.output_labels) == 186
    kinds = dict(zip(walk.output_labels, walk.output_kinds))
    assert kinds["LHipAngles_M"] == "ANGLES" and kinds["LKneeMoment_M"] == "MOMENTS"
    assert kinds["CentreOfMass_M"] == "MODELED_MARKERS" and kinds["Fwd"] == "SCALARS"
    assert kinds["PEL_MO"] == SEGMENT_POINT  # listed in no group
    assert dict(zip(static.output_labels, static.output_kinds))["LFEA"] == SEGMENT_POINT
    assert walk.output_units["ANGLES"] == "deg" and walk.output_units["MOMENTS"] == "Nmm"
    # angles are kept as stored (degrees), markers in m
    knee = walk.outputs[:, walk.output_labels.index("LKneeAngles_M"), 0]
    assert 60 < np.nanmax(knee) < 70 and 0 < np.nanmin(knee) < 10
    assert 0.5 < np.nanmax(walk.markers_m[:, walk.marker_labels.index("LASI"), 2]) < 1.5
    assert static.processing["Bodymass"] == pytest.approx(70.23, abs=1e-4)
    assert static.processing["Height"] == pytest.approx(1860.0)


def _params(groups: dict[str, list[str]]) -> dict:
    return {"POINT": {name: {"value": values} for name, values in groups.items()}}


def test_type_groups_segment_points_and_unlabelled_points_are_not_markers():
    labels = ["Sub:LASI", "Sub:LHipAngles", "Sub:LGRF", "LFEO", "PEL_MA", "*52", "Unlabeled 3", "RHJC", "LTOE"]
    params = _params({"ANGLES": ["LHipAngles"], "TYPE_GROUPS": ["ANGLES", "ANGLE", "REACTIONS_X", "REACTION"],
                      "REACTIONS_X": ["Sub:LGRF"]})  # fmt: skip
    kinds = point_kinds(params, labels)
    assert kinds == [MARKER, "ANGLES", "REACTIONS_X", SEGMENT_POINT, SEGMENT_POINT, UNLABELLED, UNLABELLED, MARKER,
                     MARKER]  # fmt: skip


def test_the_walk_s_speed_comes_from_its_markers_as_its_pelvis_gives_it():
    """Read with the model outputs as markers, the walk's mean marker speed was 0.71 m/s; its markers alone travel
    at the speed of its pelvis markers (1.275 m/s)."""
    from loper_analysis.motion.heading import travel_velocity_m_per_s

    rec = read_c3d(QCMAS / "walk-nodevice.c3d")
    pelvis = [rec.marker_labels.index(m) for m in ("LASI", "RASI", "LPSI", "RPSI")]
    v_pelvis = travel_velocity_m_per_s(rec.markers_m[:, pelvis], rec.point_rate_hz)
    v_all = travel_velocity_m_per_s(rec.markers_m, rec.point_rate_hz)
    assert np.hypot(*v_pelvis[:2]) == pytest.approx(1.275, abs=0.001)
    assert np.hypot(*v_all[:2]) == pytest.approx(np.hypot(*v_pelvis[:2]), rel=0.01)
