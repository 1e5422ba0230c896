"""The walk-through docs/first_recorded_subject.md: its commands, run as written, and the figures it quotes."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from tests.workflow_copy import copy_workflow

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials (pytest -m "not slow" leaves them out)
ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "first_recorded_subject.md"


def doc_commands() -> list[str]:
    """Every line of the walk-through's ``bash`` blocks, in order."""
    blocks = re.findall(r"```bash\n(.*?)```", DOC.read_text(), flags=re.S)
    return [line for block in blocks for line in block.splitlines() if line.strip()]


@pytest.fixture(scope="module")
def walkthrough(tmp_path_factory):
    """A fresh copy of the repository's workflow files; the doc's commands run in it one by one."""
    work = tmp_path_factory.mktemp("walkthrough")
    copy_workflow(work)
    bin_dir = str(Path(sys.executable).parent)  # loper-analysis and snakemake of this environment
    outputs = []
    for command in doc_commands():
        res = subprocess.run(
            command,
            shell=True,
            cwd=work,
            capture_output=True,
            text=True,
            timeout=900,
            env={"PATH": f"{bin_dir}:/usr/bin:/bin", "HOME": str(work)},
            executable="/bin/bash",
        )
        assert res.returncode == 0, (command, res.stderr[-3000:])
        outputs.append((command, res.stdout))
    return work, outputs


def test_the_doc_holds_the_commands_of_each_step():
    commands = doc_commands()
    assert [c.split()[0] for c in commands] == [
        "mkdir",
        "loper-analysis",
        "loper-analysis",
        "mkdir",
        "cp",
        "loper-analysis",
        "snakemake",
        "loper-analysis",
    ]


def test_inspect_reports_what_the_doc_says(walkthrough):
    work, outputs = walkthrough
    static, walk = outputs[1][1], outputs[2][1]
    assert re.search(r"Subject11:R\.Knee\s+93\.5\s+10\s+152", static)
    assert re.search(r"Subject11:R\.Toe\s+98\.0\s+3\s+152", static)
    assert "peak vertical force 433.8 N" in static and "peak vertical force 400.4 N" in static
    assert "vertical axis: +Z" in static and "matched: 41 label(s)" in static
    assert (work / "lab/label_map.tsv").read_text() == "label\tmarker\n"  # no row needed
    assert walk.count("resting (unloaded) vertical level -6.0 N") == 3
    assert re.search(r"walking direction: \+X .* at 1\.2[45] m/s", walk)


def test_the_scale_report_and_the_hand_run_agree(walkthrough):
    work, _ = walkthrough
    report = pd.read_csv(work / "results/model/R11/scale.tsv", sep="\t")
    by_hand = pd.read_csv(work / "lab/R11_scale.tsv", sep="\t")
    pd.testing.assert_frame_equal(report, by_hand)
    subject = report[report.kind == "subject"].iloc[0]
    assert round(subject.mass_kg, 3) == 85.067 and round(subject.height_m, 2) == 1.60
    assert "force plates 1, 2" in subject.source
    assert (report[report.kind == "body"][["scale_factor_x", "scale_factor_y", "scale_factor_z"]] == 1).all().all()
    assert (report.kind == "marker").sum() == 23
    assert round(1000 * report[report.kind == "markers"].marker_error_rms_m.iloc[0]) == 48
    log = (work / "results/logs/model_scaled/R11.log").read_text()
    assert "marker R.Knee missing in 10 of 11 frames of the window: averaged over the others" in log


def test_markers_ik_and_the_summary_say_what_the_doc_says(walkthrough):
    work, _ = walkthrough
    markers = pd.read_csv(work / "results/markers/R11/static.markers.tsv", sep="\t").set_index("marker")
    assert markers.loc["R.Knee", "label"] == "Subject11:R.Knee" and markers.loc["R.Knee", "n_missing_frames"] == 10
    ik = pd.read_csv(work / "results/ik/R11/walk-nodevice.ik.tsv", sep="\t").iloc[0]
    assert (ik.n_frames, ik.n_frames_solved, ik.n_frames_left_out) == (238, 238, 0)
    assert round(1000 * ik.marker_rms_mean_m, 1) == 34.8
    assert "exceeds 20 mm" in (work / "results/logs/ik/R11/walk-nodevice.log").read_text()
    summary = pd.read_csv(work / "results/strides/summary.tsv", sep="\t").iloc[0]
    assert (summary.subject, summary.status, summary.n_frames, summary.n_frames_left_out, summary.turn_deg) == (
        "R11",
        "too_few_strides",
        238,
        0,
        0.0,
    )
    assert (work / "results/grf/R11/walk-nodevice.grf.mot").is_file()


def test_the_report_is_written(walkthrough):
    work, _ = walkthrough
    html = (work / "results/report.html").read_text(errors="replace")
    assert len(html) > 100_000 and "R11" in html
