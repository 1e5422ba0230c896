"""Subject sheets as spreadsheets save them: UTF-16 ("Unicode text"), a byte-order mark, Windows line ends, trailing
tabs and empty trailing cells are read as the plain sheet; a decimal comma and a row with more filled cells than
columns are named by sheet, line and column."""

from __future__ import annotations

import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.readers import read_subject_sheet

PLAIN = (
    "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\nR01\trecorded\t\t\t1.75\t\n"
)


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


def test_the_workflow_reads_a_unicode_text_sheet_and_names_a_decimal_comma(tmp_path):
    from tests.workflow_copy import copy_workflow, snakemake

    copy_workflow(tmp_path)
    sheet = tmp_path / "config" / "subjects.tsv"
    text = sheet.read_text()
    sheet.write_bytes(
        ("\n".join(line + "\t" for line in text.splitlines()) + "\n").replace("\n", "\r\n").encode("utf-16")
    )
    res = snakemake(tmp_path, "-n", "-q")
    assert res.returncode == 0, res.stderr[-2000:]
    sheet.write_text(text.replace("1.80", "1,80"))
    res = snakemake(tmp_path, "-n", "-q")
    said = res.stdout + res.stderr
    assert res.returncode != 0
    assert "config/subjects.tsv: line 2, column 'height_m': '1,80' has a decimal comma; write 1.80" in said
