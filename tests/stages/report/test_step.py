"""The file step of the Markdown result tables (loper_analysis.stages.report.step)."""

import pandas as pd

from loper_analysis.stages.report.step import markdown_tables


def test_markdown_tables_renders_every_tsv_and_says_when_one_is_empty(tmp_path):
    pd.DataFrame({"a": [1.5]}).to_csv(tmp_path / "x.tsv", sep="\t", index=False)
    (tmp_path / "empty.tsv").write_text("\n")
    markdown_tables(["X", "Nothing"], [tmp_path / "x.tsv", tmp_path / "empty.tsv"], tmp_path / "t.md")
    text = (tmp_path / "t.md").read_text()
    assert "## X" in text and "| 1.5 |" in text and "## Nothing" in text and "(empty)" in text


def test_the_run_s_warnings_are_gathered_for_the_console(tmp_path):
    """Each trial's status other than ok and its warnings, and each scaling's warnings, one line each."""
    import pandas as pd

    from loper_analysis.stages.report.step import run_warnings

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


#: A workflow of four result files, made one rule at a time.
TINY_SNAKEFILE = """
rule all:
    input:
        "results/a.txt",
        "results/b.txt",
        "results/c.txt",
        "results/d.txt",


rule one:
    output:
        "results/{name}.txt",
    shell:
        "echo {wildcards.name} > {output}"
"""


def test_a_report_before_the_workflow_has_run_names_the_missing_results_and_the_command(tmp_path, monkeypatch, capsys):
    """After one target only, ``loper-analysis report`` stops in one line naming the first missing result files
    and ``snakemake -j2`` (with the config files given), exit status 2; after the whole run it writes the report."""
    import subprocess
    import sys

    from loper_analysis.cli import main

    (tmp_path / "Snakefile").write_text(TINY_SNAKEFILE)
    (tmp_path / "extra.yaml").write_text("note: 1\n")
    monkeypatch.chdir(tmp_path)
    subprocess.run([sys.executable, "-m", "snakemake", "-j1", "results/b.txt"], check=True, capture_output=True)
    capsys.readouterr()
    assert main(["report", "report.html"]) == 2
    err = capsys.readouterr().err
    assert err == (
        "loper-analysis report: report.html: the workflow has not built 3 of its result files (results/a.txt, "
        "results/c.txt, results/d.txt): run the whole workflow first (snakemake -j2), then the report again: no "
        "report was written\n"
    )
    assert main(["report", "report.html", "--configfile", "extra.yaml"]) == 2
    assert "(snakemake -j2 --configfile extra.yaml)" in capsys.readouterr().err
    assert not (tmp_path / "report.html").exists()
    subprocess.run([sys.executable, "-m", "snakemake", "-j1"], check=True, capture_output=True)
    assert main(["report", "report.html"]) == 0
    assert (tmp_path / "report.html").read_bytes().rstrip().endswith(b"</html>")
