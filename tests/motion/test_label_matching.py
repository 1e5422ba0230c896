"""motion/label_matching.py: lab labels paired with model markers by name, in known label sets of Plug-in Gait,
Qualisys/CAST, gait2392 and Rajagopal2016 spellings."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from loper_analysis.io.readers import read_label_map
from loper_analysis.motion.label_matching import heel_markers, landmark_indices, match_labels, starter_label_map


# moved unchanged from the inspection tests
def test_matching_rounds_and_ambiguity():
    m = match_labels(
        ["S:R_ASIS", "r.psis", "LTOE", "LANK", "LHEE", "LCAL", "C7"],
        ["R.ASIS", "R.PSIS", "L.Toe", "L.Ankle", "L.Ankle.Lat", "L.Heel", "C7"],
    )
    assert m.pairs == (
        ("S:R_ASIS", "R.ASIS", "punctuation"),
        ("r.psis", "R.PSIS", "case"),
        ("LTOE", "L.Toe", "punctuation"),
        ("C7", "C7", "exact"),
    )
    assert m.ambiguous == {"LANK": ("L.Ankle", "L.Ankle.Lat"), "LHEE": ("L.Heel",), "LCAL": ("L.Heel",)}
    assert m.unmatched_labels == ("LANK", "LHEE", "LCAL")
    assert m.unprovided_markers == ("L.Ankle", "L.Ankle.Lat", "L.Heel")
    assert match_labels(["heel_r"], ["R.Heel", "L.Heel"]).pairs == (("heel_r", "R.Heel", "synonym"),)
    assert match_labels(["RightHeel"], ["R.Heel", "L.Heel"]).pairs == (("RightHeel", "R.Heel", "synonym"),)
    assert heel_markers(["LHEE", "RHEE", "RCAL"]) is None


# new


def test_two_labels_wanting_one_marker_both_stay_unmatched():
    m = match_labels(
        ["S:LASI", "S:L_IAS", "S:C7", "S:RHEE", "S:RightKnee"], ["L.ASIS", "C7", "R.Heel", "R.Knee.Lat", "R.Knee"]
    )
    assert m.pairs == (("S:C7", "C7", "exact"), ("S:RHEE", "R.Heel", "synonym"))
    assert m.ambiguous == {
        "S:LASI": ("L.ASIS",),
        "S:L_IAS": ("L.ASIS",),
        "S:RightKnee": ("R.Knee.Lat", "R.Knee"),
    }
    assert m.unmatched_labels == ("S:LASI", "S:L_IAS", "S:RightKnee")
    assert m.unprovided_markers == ("L.ASIS", "R.Knee.Lat", "R.Knee")


def test_sides_are_never_crossed():
    m = match_labels(["RASI", "LHEE", "L_FM1", "toe_r"], ["L.ASIS", "R.Heel", "R.Toe.Med", "L.Toe"])
    assert m.pairs == ()
    assert m.unmatched_labels == ("RASI", "LHEE", "L_FM1", "toe_r")


def test_starter_map_holds_the_renamed_labels_and_reads_back(tmp_path):
    m = match_labels(["Subj:C7", "Subj:LASI", "Subj:r_fcc", "Subj:RKNE"], ["C7", "L.ASIS", "R.Heel", "R.Knee.Lat"])
    table = starter_label_map(m)
    expected = pd.DataFrame(
        [("LASI", "L.ASIS"), ("r_fcc", "R.Heel"), ("RKNE", "R.Knee.Lat")], columns=["label", "marker"], dtype=object
    )
    pd.testing.assert_frame_equal(table, expected)
    table.to_csv(tmp_path / "map.tsv", sep="\t", index=False)
    assert read_label_map(tmp_path / "map.tsv") == {"LASI": "L.ASIS", "r_fcc": "R.Heel", "RKNE": "R.Knee.Lat"}
    assert list(starter_label_map(match_labels(["S:C7"], ["C7"])).columns) == ["label", "marker"]
    assert starter_label_map(match_labels(["S:C7"], ["C7"])).empty


def test_landmark_indices_read_every_spelling_of_either_side():
    names = ["LASI", "R_IAS", "LKNE", "C7", "heel_r", "LeftHeel", "R.PSIS", "RCAL"]
    assert landmark_indices(names, ["asis", "heel"]) == [0, 1, 4, 5, 7]
    assert landmark_indices(names, ["knee_lateral"]) == [2]
    assert landmark_indices(names, ["sternum"]) == []


def test_heel_markers_of_each_marker_set():
    assert heel_markers(["LHEE", "RHEE", "LTOE"]) == {"left": "LHEE", "right": "RHEE"}
    assert heel_markers(["L_FCC", "R_FCC", "L_FM1"]) == {"left": "L_FCC", "right": "R_FCC"}
    assert heel_markers(["R.Heel", "L.Heel"]) == {"left": "L.Heel", "right": "R.Heel"}
    assert heel_markers(["calc_l", "calc_r"]) is None  # not a heel spelling
    assert heel_markers(["LHEE"]) is None


def test_the_synonym_table_is_data_and_each_spelling_has_one_landmark(tmp_path):
    import pytest
    import yaml

    from loper_analysis.errors import LoperInputError
    from loper_analysis.io.label_synonyms import LABEL_SYNONYMS_FILE, LANDMARK_SYNONYMS, read_label_synonyms

    doc = yaml.safe_load(LABEL_SYNONYMS_FILE.read_text())
    assert LANDMARK_SYNONYMS["knee_medial"] == ("kneemed", "mknee", "mkne", "knemed", "mkn", "medkn", "mfc", "fme")
    assert LANDMARK_SYNONYMS["ankle_medial"] == ("anklemed", "mankle", "mmal", "mma", "med", "medank", "tam")
    # docs/inspect.md lists every spelling of the table
    doc_text = (Path(__file__).resolve().parents[2] / "docs" / "inspect.md").read_text()
    missing = [s for entry in doc["landmarks"].values() for s in entry["spellings"] if f"`{s}`" not in doc_text]
    assert missing == []
    bad = tmp_path / "synonyms.yaml"
    bad.write_text("landmarks:\n  a: {spellings: [MED]}\n  b: {spellings: [Med.]}\n")
    with pytest.raises(LoperInputError, match="spelling 'med' belongs to landmarks 'a' and 'b'"):
        read_label_synonyms(bad)


def test_qualisys_helen_hayes_and_vicon_spellings_reach_plug_in_gait_markers():
    pig = ["LTOE", "RTOE", "LMKNE", "RMKNE", "LMMAL", "LANK", "LKNE", "LTIB", "LTHI", "CLAV"]
    m = match_labels(
        ["RLA_TOE", "LLA_TOE", "RMed_kn", "LKNEMED", "LMED", "LLMA", "LLFC", "LSHA", "LTH", "STER_NOTCH"], pig
    )
    assert {lab: mk for lab, mk, _ in m.pairs} == {
        "RLA_TOE": "RTOE",
        "LLA_TOE": "LTOE",
        "RMed_kn": "RMKNE",
        "LKNEMED": "LMKNE",
        "LMED": "LMMAL",
        "LLMA": "LANK",
        "LLFC": "LKNE",
        "LSHA": "LTIB",
        "LTH": "LTHI",
        "STER_NOTCH": "CLAV",
    }
    assert match_labels(["LMKN", "LMMA"], ["LMKNE", "LMMAL"]).unmatched_labels == ()
