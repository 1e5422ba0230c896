"""No command writes over its input: an output path that names an input (or another output) stops before any work,
naming both, and the input keeps its bytes."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from loper_analysis.cli import main

ROOT = Path(__file__).resolve().parents[2]
QCMAS = ROOT / "tests" / "data" / "c3d-parser" / "QCMAS" / "static.c3d"
GAIT2392 = ROOT / "src" / "loper_analysis" / "templates" / "gait2392_simbody.osim"


@pytest.fixture
def lab(tmp_path):
    """A copy of a lab's static trial and of a generic model, and a hard link to the trial."""
    (tmp_path / "X.c3d").write_bytes(QCMAS.read_bytes())
    (tmp_path / "G.osim").write_bytes(GAIT2392.read_bytes())
    os.link(tmp_path / "X.c3d", tmp_path / "linked.c3d")
    return tmp_path


CASES = {
    "markers": (["markers", "{d}/X.c3d", "--out", "{d}/X.c3d"], "--out", "c3d"),
    "markers, gaps over the TRC": (
        ["markers", "{d}/X.c3d", "--out", "{d}/X.trc", "--gaps", "{d}/X.trc"],
        "--gaps",
        "--out",
    ),  # fmt: skip
    "events": (["events", "{d}/X.c3d", "--out", "{d}/X.c3d"], "--out", "c3d"),
    "grf through a hard link": (["grf", "{d}/X.c3d", "--out", "{d}/linked.c3d"], "--out", "c3d"),
    "inspect, map": (
        ["inspect", "{d}/X.c3d", "--model", "{d}/G.osim", "--label-map-out", "{d}/X.c3d"],
        "--label-map-out",
        "c3d",
    ),  # fmt: skip
    "inspect, config": (["inspect", "{d}/X.c3d", "--config-out", "{d}/X.c3d"], "--config-out", "c3d"),
    "scale": (
        ["scale", "--model", "{d}/G.osim", "--setup", "{d}/s.xml", "--static", "{d}/X.c3d", "--out", "{d}/G.osim"],
        "--out",
        "--model",
    ),  # fmt: skip
    "segments": (["segments", "--model", "{d}/G.osim", "--out", "{d}/G.osim"], "--out", "--model"),
    "ik": (["ik", "--model", "{d}/G.osim", "--markers", "{d}/X.c3d", "--out", "{d}/X.c3d"], "--out", "--markers"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_an_output_over_an_input_stops_naming_both_and_leaves_it_whole(case, lab, capsys):
    argv, out_option, in_option = CASES[case]
    before = {p.name: p.read_bytes() for p in lab.iterdir()}
    assert main([a.format(d=lab) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert f"{out_option} would write over {in_option}" in err and "nothing was done" in err, err
    assert {p.name: p.read_bytes() for p in lab.iterdir()} == before
