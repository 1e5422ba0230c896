"""The workflow over subject sheets as spreadsheets save them: a UTF-16 ("Unicode text") sheet with Windows line
ends and trailing tabs is read, and a decimal comma is named by sheet, line and column (the reader itself:
tests/io/test_readers.py)."""

from __future__ import annotations


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
