"""motion/marker_templates.py: the shipped Plug-in Gait and ISB templates against their YAML (read here with
PyYAML), the fit of known label sets, and the OpenSim objects built from them."""

from __future__ import annotations

import re

import numpy as np
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.io.ik_tasks import read_ik_tasks
from loper_analysis.io.marker_templates import TEMPLATE_DIR, template_file
from loper_analysis.io.osim import read_model
from loper_analysis.motion.marker_templates import (
    derived_markers,
    template_fit,
    template_from_spec,
    template_ik_tasks,
    template_marker_set,
    template_scale_tool,
)

PIG_FILE = TEMPLATE_DIR / "plugin_gait.yaml"
#: Every Plug-in Gait marker of a full lower-body static trial (no medial markers, no knee alignment device).
PIG_LABELS = [f"{s}{c}" for s in "LR" for c in ("ASI", "PSI", "THI", "KNE", "TIB", "ANK", "HEE", "TOE")]


@pytest.fixture(scope="module")
def spec() -> dict:
    return yaml.safe_load(PIG_FILE.read_text())


@pytest.fixture(scope="module")
def pig(spec):
    return template_from_spec("plugin_gait", spec, str(PIG_FILE))


def test_sided_markers_are_expanded_and_the_left_mirrored(pig, spec):
    assert len(pig.markers) == 2 * len(spec["markers"]) + len(spec["midline_markers"]) == 25
    for code, (body, x, y, z, role) in spec["markers"].items():
        right, left = pig.marker("R" + code), pig.marker("L" + code)
        assert (right.body, left.body) == (body.format(s="r"), body.format(s="l"))
        assert right.location_m == (x, y, z) and left.location_m == (x, y, -z)
        assert right.role == left.role == role
    assert pig.marker("RASI").location_m == (0.020, 0.030, 0.128) and pig.marker("LKNE").body == "femur_l"
    assert pig.marker("SACR").location_m == (-0.160, 0.040, 0.000)
    assert pig.measurements["femur"] == (
        (("RHJC", "RKJC"), ("LHJC", "LKJC"), ("RASI", "RKNE"), ("LASI", "LKNE")),
        ("femur_r", "femur_l"),
    )
    assert pig.weights == {"anatomical": 10.0, "technical": 1.0}
    assert pig.foot_markers == {"left": "LHEE", "right": "RHEE"} and pig.side_prefix == {"left": "L", "right": "R"}


def test_bad_specs_are_refused_naming_the_key(spec):
    bad = {**spec, "markers": {**spec["markers"], "ASI": ["pelvis", 0.02, 0.03, 0.128, "bony"]}}
    with pytest.raises(
        LoperInputError, match=re.escape("t.yaml: markers.ASI: role must be one of ('anatomical', 'technical'), got")
    ):
        template_from_spec("t", bad, "t.yaml")
    bad = {**spec, "required": [*spec["required"], ["RXYZ"]]}
    with pytest.raises(
        LoperInputError, match=re.escape("t.yaml: measurements, required or foot_markers name marker(s) ['RXYZ']")
    ):
        template_from_spec("t", bad, "t.yaml")
    with pytest.raises(LoperInputError, match=re.escape("t.yaml: not a marker-set template (KeyError: 'title')")):
        template_from_spec("t", {k: v for k, v in spec.items() if k != "title"}, "t.yaml")


def test_a_knee_alignment_device_yields_the_missing_knee_marker():
    assert derived_markers(["LKAX", "LKD1", "LKD2", "RKNE"]) == {"LKNE": ("LKAX", "LKD1", "LKD2")}
    assert derived_markers(["LKAX", "LKD1", "LKD2", "LKNE"]) == {}
    assert derived_markers(["LKAX", "LKD1"]) == {}
    isb = {"left": "L_", "right": "R_"}
    assert derived_markers(["R_KAX", "R_KD1", "R_KD2"], isb) == {"R_KNE": ("R_KAX", "R_KD1", "R_KD2")}


def test_label_sets_fit_or_name_the_missing_groups(pig):
    fit = template_fit([f"Subj:{lab}" for lab in PIG_LABELS], pig)
    assert fit.fits and fit.share == 1.0 and set(fit.found) == set(PIG_LABELS)
    kad = [lab for lab in PIG_LABELS if lab != "RKNE"] + ["RKAX", "RKD1", "RKD2"]
    fit = template_fit(kad, pig)
    assert fit.fits and "RKNE" in fit.found
    fit = template_fit([lab for lab in PIG_LABELS if lab not in ("LTOE", "RTOE", "LPSI")] + ["SACR"], pig)
    assert fit.missing_groups == (("LTOE",), ("RTOE",))
    assert fit.share == pytest.approx(10 / 12, rel=1e-12) and not fit.fits


def test_ik_tasks_weigh_each_role_and_read_back(pig, tmp_path):
    walking = ["LASI", "RASI", "LTHI", "RKNE", "LMKNE"]
    table = template_ik_tasks(pig, walking)
    path = tmp_path / "tasks.tsv"
    table.to_csv(path, sep="\t", index=False)
    markers, coordinates = read_ik_tasks(path)
    assert markers == {"RASI": 10.0, "LASI": 10.0, "LTHI": 1.0, "RKNE": 10.0, "LMKNE": 10.0}
    assert coordinates == {
        c: (1000.0, 0.0) for c in ("subtalar_angle_r", "subtalar_angle_l", "mtp_angle_r", "mtp_angle_l")
    }


def test_the_marker_set_places_each_marker_on_its_body(pig):
    names = ["LASI", "RTHI", "LKNE", "C7"]
    ms = template_marker_set(pig, names)
    assert ms.getSize() == 4
    for i in range(ms.getSize()):
        marker = ms.get(i)
        expected = pig.marker(marker.getName())
        assert marker.getParentFrameName() == f"/bodyset/{expected.body}"
        loc = marker.get_location()
        assert (loc.get(0), loc.get(1), loc.get(2)) == expected.location_m
        assert marker.get_fixed() == (expected.role == "anatomical")
    assert template_marker_set(pig).getSize() == 25


def test_the_scale_tool_uses_the_pairs_present(pig):
    present = [lab for lab in PIG_LABELS if lab != "LTOE"] + ["CLAV"]
    tool = template_scale_tool(pig, present, "marker_set.xml")
    assert tool.getName() == "plugin_gait"
    assert tool.getGenericModelMaker().getMarkerSetFileName() == "marker_set.xml"
    measurements = tool.getModelScaler().getMeasurementSet()
    pairs = {}
    for i in range(measurements.getSize()):
        m = measurements.get(i)
        ps = m.getMarkerPairSet()
        pairs[m.getName()] = [(ps.get(k).getMarkerName(0), ps.get(k).getMarkerName(1)) for k in range(ps.getSize())]
    assert pairs == {
        "pelvis": [("RASI", "LASI")],
        "torso": [("RASI", "CLAV"), ("LASI", "CLAV")],
        "femur": [("RASI", "RKNE"), ("LASI", "LKNE")],
        "tibia": [("RKNE", "RANK"), ("LKNE", "LANK")],
        "foot": [("RHEE", "RTOE")],  # LTOE is missing
    }
    tasks = tool.getMarkerPlacer().getIKTaskSet()
    weights = {tasks.get(i).getName(): tasks.get(i).getWeight() for i in range(tasks.getSize())}
    assert weights["LTHI"] == 1.0 and weights["RASI"] == 10.0 and weights["CLAV"] == 1.0
    assert weights["subtalar_angle_r"] == 1000.0 and "LTOE" not in weights
    assert len(weights) == len(present) + 4


def test_with_the_model_the_centres_are_the_models_joints_and_every_other_marker_moves(pig):
    """The calibration's virtual markers sit at gait2392's own joints (the hip's place in the pelvis as the model
    file writes it, the knee's at zero flexion, the ankle's), the pelvis's 0.1 m forward of the hips along the
    template's spines (and as far behind), each foot's 0.1 m above and below the ankle; they alone are fixed."""
    model = read_model(template_file(pig.model))
    present = [*PIG_LABELS, "CLAV"]
    ms = template_marker_set(pig, present, model)
    got = {ms.get(i).getName(): ms.get(i) for i in range(ms.getSize())}
    virtual = {"LHJC", "RHJC", "LKJC", "RKJC", "LAJC", "RAJC", "PELVIS_FRONT", "PELVIS_BACK", "LFOOT_UP", "LFOOT_DOWN",
               "RFOOT_UP", "RFOOT_DOWN", "LKNEE_LAT", "LKNEE_MED", "RKNEE_LAT", "RKNEE_MED"}  # fmt: skip
    assert set(got) == set(present) | virtual

    def place(name):
        loc = got[name].get_location()
        return got[name].getParentFrameName(), np.array([loc.get(0), loc.get(1), loc.get(2)])

    frame, hip = place("RHJC")
    assert frame == "/bodyset/pelvis"
    np.testing.assert_allclose(hip, [-0.0707, -0.0661, 0.0835], atol=1e-12)  # hip_r's location in the pelvis
    frame, knee = place("LKJC")
    assert frame == "/bodyset/femur_l"
    np.testing.assert_allclose(knee, [-0.0045, -0.3958, 0.0], atol=1e-4)  # knee_l's translation at 0 flexion
    assert place("LAJC")[0] == "/bodyset/tibia_l"
    np.testing.assert_allclose(place("LAJC")[1], [0.0, -0.43, 0.0], atol=1e-12)  # ankle_l's location in tibia_l
    frame, forward = place("PELVIS_FRONT")
    assert frame == "/bodyset/pelvis"
    spines = np.array(pig.marker("LASI").location_m) - np.array(pig.marker("LPSI").location_m)
    spines[2] = 0.0
    np.testing.assert_allclose(forward - [-0.0707, -0.0661, 0.0], 0.1 * spines / np.linalg.norm(spines), atol=1e-12)
    frame, up = place("RFOOT_UP")
    assert frame == "/bodyset/talus_r"
    np.testing.assert_allclose(up, [0.0, 0.1, 0.0], atol=1e-12)  # gait2392's talus stands upright at 0
    assert {n for n, m in got.items() if m.get_fixed()} == virtual


def test_with_the_centres_present_the_scale_tool_measures_between_them(pig):
    tool = template_scale_tool(pig, [*PIG_LABELS, "CLAV"], "marker_set.xml")
    measurements = tool.getModelScaler().getMeasurementSet()
    pairs = {}
    for i in range(measurements.getSize()):
        ps = measurements.get(i).getMarkerPairSet()
        pairs[measurements.get(i).getName()] = [
            (ps.get(k).getMarkerName(0), ps.get(k).getMarkerName(1)) for k in range(ps.getSize())
        ]
    assert pairs["pelvis"] == [("RHJC", "LHJC")]
    assert pairs["femur"] == [("RHJC", "RKJC"), ("LHJC", "LKJC")]
    assert pairs["tibia"] == [("RKJC", "RAJC"), ("LKJC", "LAJC")]
    assert pairs["foot"] == [("RHEE", "RTOE"), ("LHEE", "LTOE")]
    tasks = tool.getMarkerPlacer().getIKTaskSet()
    weights = {tasks.get(i).getName(): tasks.get(i).getWeight() for i in range(tasks.getSize())}
    assert weights["RKJC"] == weights["PELVIS_BACK"] == weights["LFOOT_UP"] == 1000.0
    assert weights["RASI"] == weights["LTHI"] == 0.1  # only what the centres leave free
