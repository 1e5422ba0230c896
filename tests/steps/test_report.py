"""The file step of the Markdown result tables (loper_analysis.steps.report)."""

import pandas as pd

from loper_analysis.steps.report import markdown_tables


def test_markdown_tables_renders_every_tsv_and_says_when_one_is_empty(tmp_path):
    pd.DataFrame({"a": [1.5]}).to_csv(tmp_path / "x.tsv", sep="\t", index=False)
    (tmp_path / "empty.tsv").write_text("\n")
    markdown_tables(["X", "Nothing"], [tmp_path / "x.tsv", tmp_path / "empty.tsv"], tmp_path / "t.md")
    text = (tmp_path / "t.md").read_text()
    assert "## X" in text and "| 1.5 |" in text and "## Nothing" in text and "(empty)" in text


def test_the_run_s_warnings_are_gathered_for_the_console(tmp_path):
    """Each trial's status other than ok and its warnings, and each scaling's warnings, one line each."""
    import pandas as pd

    from loper_analysis.steps.report import run_warnings

    summary = tmp_path / "summary.tsv"
    pd.DataFrame(
        {"subject": ["S1", "S1"], "trial": ["walk", "pert"], "status": ["ok", "too_few_strides"],
         "warnings": ["knee_left flexes negative", ""]}
    ).to_csv(summary, sep="\t", index=False)  # fmt: skip
    scale = tmp_path / "scale.tsv"
    pd.DataFrame({"kind": ["subject", "warning"], "source": ["mass: given", "static pose: hip_left -22.0 deg"]}).to_csv(
        scale, sep="\t", index=False
    )
    assert run_warnings(summary, [scale, tmp_path / "absent.tsv"]) == [
        f"{scale}: static pose: hip_left -22.0 deg",
        "S1 walk: knee_left flexes negative",
        "S1 pert: too_few_strides",
    ]
    assert run_warnings(tmp_path / "none.tsv") == []
