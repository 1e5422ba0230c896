"""Lab labels to model-marker names (loper_analysis.motion.marker_names) and the label-map file reader."""

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.readers import read_label_map
from loper_analysis.motion.marker_names import (
    missing_model_markers,
    model_marker_names,
    require_model_markers,
    strip_subject_prefix,
)

SOURCE = "data/raw/S01/walk01.c3d"
VICON = ["Anna:LASIS", "Anna:RASIS", "Anna:L_KNEE", "Anna:LHEE", "*12"]


@pytest.mark.parametrize(
    "label, name",
    [
        ("Subject:LASI", "LASI"),
        ("LASI", "LASI"),
        ("Lab:Anna:LASI", "LASI"),
        (" Anna:RHEE ", "RHEE"),
        ("*3", "*3"),
    ],
)
def test_subject_prefix_is_everything_up_to_the_last_colon(label, name):
    assert strip_subject_prefix(label) == name


def test_prefixes_stripped_and_map_applied_by_short_or_full_label():
    names = model_marker_names(VICON, {"LASIS": "LASI", "Anna:RASIS": "RASI", "L_KNEE": "LKNE"}, SOURCE)
    assert names == ["LASI", "RASI", "LKNE", "LHEE", "*12"]
    assert model_marker_names(VICON, None, SOURCE) == ["LASIS", "RASIS", "L_KNEE", "LHEE", "*12"]


def test_map_entry_for_a_label_the_file_lacks_is_named():
    with pytest.raises(LoperInputError) as err:
        model_marker_names(VICON, {"LASIS": "LASI", "R_ASIS": "RASI"}, SOURCE)
    message = str(err.value)
    assert message.startswith(f"{SOURCE}: markers.label_map: label(s) R_ASIS not in the file")
    assert "LASIS, RASIS, L_KNEE, LHEE, *12" in message


@pytest.mark.parametrize(
    "labels, label_map, detail",
    [
        (["A:LASI", "B:LASI"], None, "LASI from A:LASI, B:LASI"),
        (["LASIS", "LASI"], {"LASIS": "LASI"}, "LASI from LASIS, LASI"),
    ],
)
def test_two_labels_with_one_name_are_refused(labels, label_map, detail):
    with pytest.raises(LoperInputError, match="marker names must be unique") as err:
        model_marker_names(labels, label_map, SOURCE)
    assert detail in str(err.value) and SOURCE in str(err.value)


def test_map_value_must_be_a_name():
    with pytest.raises(LoperInputError, match="markers.label_map: 'LASIS' maps to 'L ASI'"):
        model_marker_names(VICON, {"LASIS": "L ASI"}, SOURCE)


def test_required_model_markers_no_label_provides_are_listed():
    names = model_marker_names(VICON, {"LASIS": "LASI"}, SOURCE)
    required = ["LASI", "RASI", "LKNE", "LHEE", "RHEE"]
    assert missing_model_markers(names, required) == ["RASI", "LKNE", "RHEE"]
    require_model_markers(names, ["LASI", "LHEE"], SOURCE)  # all present: no error
    with pytest.raises(LoperInputError) as err:
        require_model_markers(names, required, SOURCE, VICON)
    message = str(err.value)
    assert message.startswith(f"{SOURCE}: model marker(s) RASI, LKNE, RHEE not provided by any label")
    assert "markers.label_map" in message and "Anna:RASIS" in message


def test_label_map_files_tsv_and_yaml(tmp_path):
    tsv = tmp_path / "map.tsv"
    tsv.write_text("label\tmarker\tnote\nLASIS\tLASI\tpelvis\nAnna:L_KNEE\tLKNE\t\n")
    yml = tmp_path / "map.yaml"
    yml.write_text("LASIS: LASI\n'Anna:L_KNEE': LKNE\n")
    expected = {"LASIS": "LASI", "Anna:L_KNEE": "LKNE"}
    assert read_label_map(tsv) == expected
    assert read_label_map(yml) == expected
    assert model_marker_names(VICON, read_label_map(tsv))[:3] == ["LASI", "RASIS", "LKNE"]


def test_labels_with_inner_spaces_are_kept_and_mapped_by_a_key_with_spaces(tmp_path):
    """BTS labels: a key with spaces renames them (inline, YAML or TSV map); unmapped ones keep their spaces."""
    bts = ["Anna:r heel", "l heel", "r toe tip"]
    assert model_marker_names(bts, None, SOURCE) == ["r heel", "l heel", "r toe tip"]
    yaml_map = tmp_path / "map.yaml"
    yaml_map.write_text("r heel: RHEE\nl heel: LHEE\n")
    tsv_map = tmp_path / "map.tsv"
    tsv_map.write_text("label\tmarker\nr heel\tRHEE\nl heel\tLHEE\n")
    for label_map in ({"r heel": "RHEE", "l heel": "LHEE"}, read_label_map(yaml_map), read_label_map(tsv_map)):
        assert model_marker_names(bts, label_map, SOURCE) == ["RHEE", "LHEE", "r toe tip"]
    with pytest.raises(LoperInputError, match=r"markers\.label_map: label\(s\) r  heel not in the file"):
        model_marker_names(bts, {"r  heel": "RHEE"}, SOURCE)  # a key matches the label exactly
    with pytest.raises(LoperInputError, match=r"'r heel' maps to 'R HEE', not a marker name \(non-empty, no spaces"):
        model_marker_names(bts, {"r heel": "R HEE"}, SOURCE)
