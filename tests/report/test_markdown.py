"""Markdown rendering of result tables (loper_analysis.report.markdown)."""

import pandas as pd

from loper_analysis.report.markdown import markdown_document, markdown_table


def test_markdown_table_formats_numbers_and_gaps():
    frame = pd.DataFrame({"joint": ["hip", "knee"], "K": [55.123456, float("nan")], "n": [12, 3]})
    assert markdown_table(frame) == "| joint | K | n |\n|---|---|---|\n| hip | 55.12 | 12 |\n| knee |  | 3 |\n"


def test_markdown_document_sections():
    text = markdown_document([("X", "x.tsv", pd.DataFrame({"a": [1.5]})), ("Nothing", "empty.tsv", pd.DataFrame())])
    assert "## X" in text and "| 1.5 |" in text and "## Nothing" in text and "(empty)" in text
