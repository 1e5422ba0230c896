"""Choosing a subject's marker-set template from its labels (loper_analysis.subject_setup): the template, the
markers of the static and walking trials, the labels left over, and what is said when no template fits."""

from __future__ import annotations

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.stages.templates import read_templates
from loper_analysis.subject_setup import NoTemplateFits, format_fits, subject_setup

#: Plug-in Gait's lower-body markers as a walking trial holds them.
WALK = ["LASI", "RASI", "LPSI", "RPSI", "LKNE", "RKNE", "LANK", "RANK", "LHEE", "RHEE", "LTOE", "RTOE", "LTHI", "RTHI"]


def test_a_knee_alignment_device_stands_in_for_the_knee_marker_of_the_static_trial():
    walk = [lab for lab in ["LASI", "RASI", "LPSI", "RPSI", "LKNE", "RKNE", "LANK", "RANK", "LHEE", "RHEE", "LTOE",
                            "RTOE", "LTHI", "RTHI"]]  # fmt: skip
    static = [lab for lab in walk if lab not in ("LKNE", "RKNE")] + ["LKAX", "LKD1", "LKD2", "RKAX", "RKD1", "RKD2"]
    setup = subject_setup(static, [walk], read_templates())
    assert setup.template.name == "plugin_gait"
    assert {"LKNE", "RKNE"} <= set(setup.static_markers) and setup.static_only == ()
    assert set(setup.unmapped) == {"LKAX", "LKD1", "LKD2", "RKAX", "RKD1", "RKD2"}


def test_a_marker_missing_from_a_walking_trial_is_tracked_in_no_walking_trial():
    """Subject prefixes are stripped; a label of no template is kept aside; the medial knee markers and the thigh
    marker one walking trial lacks are the static trial's only."""
    static = [f"S1:{m}" for m in [*WALK, "LMKNE", "RMKNE", "FOO"]]
    walking = [[f"S1:{m}" for m in WALK if m != "RTHI"], [f"S1:{m}" for m in WALK]]
    setup = subject_setup(static, walking, read_templates())
    assert setup.template.name == "plugin_gait" and setup.fits[0].template.name == "plugin_gait"
    assert setup.static_markers == (*WALK, "LMKNE", "RMKNE")
    assert setup.walking_markers == ("LASI", "RASI", "LPSI", "RPSI", "LTHI", "LKNE", "RKNE", "LANK", "RANK", "LHEE",
                                     "RHEE", "LTOE", "RTOE")  # fmt: skip
    assert setup.static_only == ("RTHI", "LMKNE", "RMKNE")
    assert setup.unmapped == ("FOO",)
    assert setup.label_map.empty  # every label is its marker's name
    tracked = setup.ik_tasks[setup.ik_tasks.kind == "marker"]
    assert list(tracked.name) == list(setup.walking_markers)
    assert tracked.set_index("name").weight.to_dict()["LTHI"] == 1.0


def test_without_a_static_trial_the_first_walking_trial_stands_in():
    setup = subject_setup(None, [WALK], read_templates())
    assert setup.static_markers == tuple(WALK) and set(setup.walking_markers) == set(WALK)
    assert setup.static_only == ()


def test_each_templates_fit_is_one_line_best_first():
    setup = subject_setup(None, [WALK], read_templates())
    assert format_fits(setup.fits).splitlines() == [
        "  plugin_gait  12 of 12 required, 14 of 25 markers; missing nothing",
        "  isb          10 of 12 required, 12 of 46 markers; missing L_FM2 or L_FM1 or L_FM5, R_FM2 or R_FM1 or R_FM5",
    ]


def test_labels_that_fit_no_template_name_the_closest_and_what_it_misses():
    with pytest.raises(NoTemplateFits) as info:
        subject_setup(["A", "B", "LASI"], [["A", "B", "LASI"]], read_templates(), source="x.c3d")
    message = str(info.value)
    assert message.startswith("x.c3d: the labels fit no marker-set template; closest: isb (")
    assert "), 1 of 12 required markers found; missing: R_IAS, L_IPS or SACR, R_IPS or SACR, L_FLE, " in message
    assert message.endswith("; labels mapped: LASI->L_IAS; labels left without a marker: A, B")
    assert [f.template.name for f in info.value.fits] == ["isb", "plugin_gait"]
    with pytest.raises(LoperInputError, match=r"^x.c3d: no marker-set template to choose from$"):
        subject_setup(["A"], [], {}, source="x.c3d")
