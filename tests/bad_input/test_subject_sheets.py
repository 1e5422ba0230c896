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


def test_a_subject_named_na_goes_through_as_a_name(tmp_path):
    """``NA`` fits the subject IDs' rule; pandas would read it as missing. A short synthetic study of subject NA
    builds its strides summary and transparency table with the subject named, exit 0."""
    import pandas as pd
    import yaml

    from tests.workflow_copy import copy_workflow, snakemake

    copy_workflow(tmp_path)
    (tmp_path / "config" / "subjects.tsv").write_text(
        "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nNA\tsynthetic\tfemale\t25\t1.65\t60.0\n"
    )
    cfg = yaml.safe_load((tmp_path / "config" / "config.yaml").read_text())
    cfg["synthetic"]["walking_duration_s"] = 25.0
    cfg["device"]["subject"] = "NA"
    (tmp_path / "config" / "config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    res = snakemake(tmp_path, "results/strides/summary.tsv", "results/transparency/rmsd.tsv")
    assert res.returncode == 0, res.stderr[-3000:]
    for table, expected in (("results/strides/summary.tsv", {"NA"}), ("results/transparency/rmsd.tsv", {"NA", "all"})):
        subjects = pd.read_csv(tmp_path / table, sep="\t", keep_default_na=False)["subject"]
        assert set(subjects) == expected, table  # "all": the across-subject rows
