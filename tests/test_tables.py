"""Markdown rendering of result tables."""

import pandas as pd

from loper_analysis.tables import markdown_table, write_markdown


def test_markdown_table_formats_numbers_and_gaps():
    frame = pd.DataFrame({"joint": ["hip", "knee"], "K": [55.123456, float("nan")], "n": [12, 3]})
    assert markdown_table(frame) == "| joint | K | n |\n|---|---|---|\n| hip | 55.12 | 12 |\n| knee |  | 3 |\n"


def test_write_markdown_sections(tmp_path):
    pd.DataFrame({"a": [1.5]}).to_csv(tmp_path / "x.tsv", sep="\t", index=False)
    (tmp_path / "empty.tsv").write_text("\n")
    write_markdown({"X": tmp_path / "x.tsv", "Nothing": tmp_path / "empty.tsv"}, tmp_path / "t.md")
    text = (tmp_path / "t.md").read_text()
    assert "## X" in text and "| 1.5 |" in text and "## Nothing" in text and "(empty)" in text
