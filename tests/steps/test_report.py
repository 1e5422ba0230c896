"""The file step of the Markdown result tables (loper_analysis.steps.report)."""

import pandas as pd

from loper_analysis.steps.report import markdown_tables


def test_markdown_tables_renders_every_tsv_and_says_when_one_is_empty(tmp_path):
    pd.DataFrame({"a": [1.5]}).to_csv(tmp_path / "x.tsv", sep="\t", index=False)
    (tmp_path / "empty.tsv").write_text("\n")
    markdown_tables(["X", "Nothing"], [tmp_path / "x.tsv", tmp_path / "empty.tsv"], tmp_path / "t.md")
    text = (tmp_path / "t.md").read_text()
    assert "## X" in text and "| 1.5 |" in text and "## Nothing" in text and "(empty)" in text
