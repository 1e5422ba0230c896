"""The readers (io.readers): TSV tables, YAML documents and whole files read back as written; label maps from
TSV, YAML, inline or merged; subject sheets as spreadsheets save them; and bad files named by file, line, column
and value."""

from __future__ import annotations

import errno
import os

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.readers import (
    read_bytes,
    read_label_map,
    read_label_maps,
    read_subject_sheet,
    read_tsv,
    read_yaml,
)

PLAIN = (
    "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\nR01\trecorded\t\t\t1.75\t\n"
)


def test_a_tsv_table_reads_back_as_written(tmp_path, rng):
    table = pd.DataFrame({"side": ["l", "r", "l"], "time_s": rng.uniform(0, 10, 3), "stride": [1, 1, 2]})
    path = tmp_path / "events.tsv"
    table.to_csv(path, sep="\t", index=False, float_format="%.17g")
    back = read_tsv(path, "event table", ("side", "time_s"))
    pd.testing.assert_frame_equal(back, table)
    np.testing.assert_array_equal(back["time_s"].to_numpy(), table["time_s"].to_numpy())


def test_an_empty_tsv_is_an_empty_table_and_a_header_alone_needs_no_columns(tmp_path):
    empty = tmp_path / "empty.tsv"
    empty.write_bytes(b"")
    assert read_tsv(empty, "event table", ("side",)).shape == (0, 0)
    blank = tmp_path / "blank.tsv"
    blank.write_text("\n")
    assert read_tsv(blank, "event table", ("side",)).shape == (0, 0)
    header = tmp_path / "header.tsv"
    header.write_text("a\tb\n")
    table = read_tsv(header, "event table", ("side",))  # no rows: the required columns are not asked for
    assert list(table.columns) == ["a", "b"] and len(table) == 0


def test_a_tsv_missing_a_column_or_its_file_is_named(tmp_path):
    path = tmp_path / "events.tsv"
    path.write_text("side\ttime\nl\t0.5\n")
    with pytest.raises(LoperInputError) as err:
        read_tsv(path, "event table", ("side", "time_s", "event"))
    assert str(err.value) == (f"{path}: event table: column(s) ['time_s', 'event'] missing (has ['side', 'time'])")
    with pytest.raises(LoperInputError) as err:
        read_tsv(tmp_path / "none.tsv", "stride table")
    assert str(err.value) == f"{tmp_path / 'none.tsv'}: stride table not found"


def test_an_unparsable_tsv_is_named(tmp_path):
    path = tmp_path / "ragged.tsv"
    path.write_text("a\tb\n1\t2\n3\t4\t5\t6\n")
    with pytest.raises(LoperInputError, match=rf"^{path}: cannot read the cycle table \(.*line 3"):
        read_tsv(path, "cycle table")


def test_whole_files_read_back_their_bytes_and_a_missing_one_is_named(tmp_path, rng):
    data = rng.integers(0, 256, 1000, dtype=np.uint8).tobytes()
    path = tmp_path / "figure.png"
    path.write_bytes(data)
    assert read_bytes(path, "figure") == data
    with pytest.raises(LoperInputError) as err:
        read_bytes(tmp_path / "none.png", "figure")
    assert str(err.value) == f"{tmp_path / 'none.png'}: cannot read the figure ({os.strerror(errno.ENOENT)})"


def test_a_yaml_document_reads_back_and_invalid_yaml_is_named(tmp_path):
    path = tmp_path / "doc.yaml"
    path.write_text("subject: S01\nheight_m: 1.75\nonsets_ms: [50, 175]\n")
    assert read_yaml(path) == {"subject": "S01", "height_m": 1.75, "onsets_ms": [50, 175]}
    bad = tmp_path / "bad.yaml"
    bad.write_text("subject: [S01\n")
    with pytest.raises(LoperInputError, match=rf"^{bad}: not a readable truth file \("):
        read_yaml(bad, "truth file")
    with pytest.raises(LoperInputError, match=rf"^{tmp_path / 'none.yaml'}: not a readable YAML file \("):
        read_yaml(tmp_path / "none.yaml")


def test_label_map_edge_blanks_are_stripped_and_an_empty_tsv_is_an_empty_map(tmp_path):
    tsv = tmp_path / "map.tsv"
    tsv.write_text("label\tmarker\n LASIS \tLASI \n")
    assert read_label_map(tsv) == {"LASIS": "LASI"}
    empty = tmp_path / "empty.tsv"
    empty.write_text("label\tmarker\n")
    assert read_label_map(empty) == {}
    with pytest.raises(LoperInputError, match=rf"^{tmp_path / 'none.yml'}: label map not found$"):
        read_label_map(tmp_path / "none.yml")


@pytest.mark.parametrize(
    "name, text, match",
    [
        ("twice.tsv", "label\tmarker\nLASIS\tLASI\nLASIS\tRASI\n", "names label 'LASIS' twice"),
        ("blank.tsv", "label\tmarker\nLASIS\t\n", "entry 1: 'LASIS' -> '' is not a pair of names"),
        ("cols.tsv", "lab\tmarker\nLASIS\tLASI\n", r"column\(s\) \['label'\] missing"),
        ("list.yaml", "- LASIS\n- LASI\n", "must be a YAML mapping"),
    ],
)
def test_bad_label_map_files_are_named(tmp_path, name, text, match):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(LoperInputError, match=match) as err:
        read_label_map(path)
    assert str(path) in str(err.value)


def test_label_maps_inline_from_a_file_or_merged_later_wins(tmp_path):
    path = tmp_path / "kind.yaml"
    path.write_text("LASIS: LASI\nRHEEL: RHEE\n")
    assert read_label_maps(None) is None
    inline = {"LASIS": "L_ASI"}
    assert read_label_maps(inline) == inline and read_label_maps(inline) is not inline
    assert read_label_maps(str(path)) == {"LASIS": "LASI", "RHEEL": "RHEE"}
    merged = read_label_maps([{"LASIS": "X", "LTOE": "LTOE"}, path, {"RHEEL": "RHE2"}, None])
    assert merged == {"LASIS": "LASI", "LTOE": "LTOE", "RHEEL": "RHE2"}


@pytest.mark.parametrize(
    "how",
    ["utf-16", "utf-8 with a byte-order mark", "windows line ends", "trailing tabs", "comments and blank lines"],
)
def test_a_sheet_saved_by_a_spreadsheet_reads_as_the_plain_sheet(how, tmp_path):
    plain = tmp_path / "plain.tsv"
    plain.write_text(PLAIN)
    saved = tmp_path / "saved.tsv"
    text = PLAIN
    if how == "windows line ends":
        text = text.replace("\n", "\r\n")
    if how == "trailing tabs":
        text = "\n".join(line + "\t\t" for line in text.splitlines()) + "\n"
    if how == "comments and blank lines":
        text = "# our subjects\n\n" + text + "\n"
    encoded = {"utf-16": text.encode("utf-16"), "utf-8 with a byte-order mark": text.encode("utf-8-sig")}
    saved.write_bytes(encoded.get(how, text.encode("utf-8")))
    expected = pd.read_csv(plain, sep="\t", dtype={"subject": str})
    pd.testing.assert_frame_equal(read_subject_sheet(saved), expected)
    assert read_subject_sheet(saved).loc[1, "height_m"] == 1.75


def test_a_decimal_comma_is_named_at_its_own_line_and_column(tmp_path):
    sheet = tmp_path / "subjects.tsv"
    sheet.write_text(PLAIN.replace("1.75", "1,75"))
    with pytest.raises(LoperInputError, match=r"subjects.tsv: line 3, column 'height_m': '1,75' has a decimal comma"):
        read_subject_sheet(sheet)


def test_a_row_with_more_filled_cells_than_columns_is_named(tmp_path):
    sheet = tmp_path / "subjects.tsv"
    sheet.write_text(PLAIN + "S02\tsynthetic\tfemale\t25\t1.62\t56.0\tleft-handed\n")
    with pytest.raises(LoperInputError, match=r"line 4: 7 cells for the header's 6 columns .*'left-handed'"):
        read_subject_sheet(sheet)


def test_a_sheet_in_latin_1_keeps_its_accents_and_its_numbers(tmp_path):
    sheet = tmp_path / "subjects.tsv"
    sheet.write_bytes("subject\tnote\theight_m\nS01\tgroße Füße\t1.80\n".encode("latin-1"))
    table = read_subject_sheet(sheet)
    assert table.loc[0, "note"] == "große Füße" and table.loc[0, "height_m"] == 1.80


def test_a_word_for_a_number_an_empty_sheet_and_a_missing_one_are_named(tmp_path):
    sheet = tmp_path / "subjects.tsv"
    sheet.write_text(PLAIN.replace("72.0", "72 kg"))
    with pytest.raises(LoperInputError) as err:
        read_subject_sheet(sheet)
    assert str(err.value) == f"{sheet}: line 2, column 'mass_kg': '72 kg' is not a number"
    sheet.write_text("# no subjects yet\n\n")
    with pytest.raises(LoperInputError, match=rf"^{sheet}: the subject sheet is empty \(no header line\)$"):
        read_subject_sheet(sheet)
    with pytest.raises(LoperInputError, match=rf"^{tmp_path / 'none.tsv'}: subject sheet not found$"):
        read_subject_sheet(tmp_path / "none.tsv")


def test_a_subject_or_trial_named_like_a_missing_value_stays_a_name(tmp_path):
    """The subject IDs' rule allows ``NA``, ``None``, ``null``, ``nan``: the sheet and every table the pipeline
    writes read them back as names; a number column still reads an empty cell (and ``NA``) as missing."""
    from loper_analysis.io.atomic import write_tsv
    from loper_analysis.io.readers import read_subject_sheet, read_tsv

    sheet = tmp_path / "subjects.tsv"
    sheet.write_text("subject\tsource\tmass_kg\nNA\tsynthetic\t70\nnull\trecorded\t\nnan\trecorded\t61.5\n")
    read = read_subject_sheet(sheet)
    assert read["subject"].tolist() == ["NA", "null", "nan"] and read["mass_kg"].isna().tolist() == [False, True, False]
    table = pd.DataFrame({"subject": ["NA", "None"], "trial": ["null", "walk"], "rmsd_rad": [np.nan, 0.25]})
    write_tsv(table, tmp_path / "t.tsv")
    back = read_tsv(tmp_path / "t.tsv")
    assert back["subject"].tolist() == ["NA", "None"] and back["trial"].tolist() == ["null", "walk"]
    assert np.isnan(back["rmsd_rad"][0]) and back["rmsd_rad"][1] == 0.25
    (tmp_path / "n.tsv").write_text("subject\tx\nS01\tNA\n")  # another tool's NA in a number column: missing
    assert np.isnan(read_tsv(tmp_path / "n.tsv")["x"][0])
