"""Heel markers given for the wrong feet stop the events step: on the real walks (the seven clinical labs' and
OpenSim's walking5) the left heel lies left of the right heel along the pelvis's right axis, each by its measured
figure; given the other way round, the step stops naming the option, the markers and the swap to try.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from loper_analysis.cli import main
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.foot_checks import heel_lateral_offset_m
from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.label_matching import heel_markers
from loper_analysis.stages.events.step import EventSettings, events

DATA = Path(__file__).resolve().parents[1] / "data"
LABS = ("AUC", "FMC", "MH", "QCMAS", "RBWH", "RCH", "SYD")
WALKS = [f"c3d-parser/{lab}/walk-nodevice.c3d" for lab in LABS] + ["opensim-core/walking5.c3d"]

#: The left heel's mean position relative to the right heel along the pelvis's right axis (LASI -> RASI), mm,
#: measured on the files as stored.
HEEL_OFFSET_MM = {
    "c3d-parser/AUC/walk-nodevice.c3d": -83,
    "c3d-parser/FMC/walk-nodevice.c3d": -113,
    "c3d-parser/MH/walk-nodevice.c3d": -124,
    "c3d-parser/QCMAS/walk-nodevice.c3d": -94,
    "c3d-parser/RBWH/walk-nodevice.c3d": -60,
    "c3d-parser/RCH/walk-nodevice.c3d": -173,
    "c3d-parser/SYD/walk-nodevice.c3d": -122,
    "opensim-core/walking5.c3d": -90,
}


def _names(path: Path) -> list[str]:
    return [label.split(":")[-1] for label in read_c3d(path).marker_labels]


@pytest.mark.parametrize("walk", WALKS)
def test_each_walks_left_heel_lies_left_of_the_right_heel(walk):
    path = DATA / walk
    names, X = _names(path), read_c3d(path).markers_m
    feet = heel_markers(names)
    offset = heel_lateral_offset_m(*(X[:, names.index(m)] for m in (feet["left"], feet["right"], "LASI", "RASI")))
    assert offset * 1000 == pytest.approx(HEEL_OFFSET_MM[walk], abs=1)
    swapped = heel_lateral_offset_m(*(X[:, names.index(m)] for m in (feet["right"], feet["left"], "LASI", "RASI")))
    assert swapped == pytest.approx(-offset)


def test_heels_given_for_the_other_feet_stop_the_events_command(tmp_path, capsys):
    out = tmp_path / "w5.events.tsv"
    walking5 = DATA / "opensim-core/walking5.c3d"
    assert main(["events", str(walking5), "--out", str(out), "--feet", "RCAL", "LCAL"]) == 2
    err = capsys.readouterr().err
    assert (
        f"{walking5}: events.foot_markers (--feet) left RCAL, right LCAL: the heel given for the left foot lies 90 mm "
        "to the right of the one given for the right foot"
    ) in err
    assert "(here perhaps left LCAL, right RCAL)" in err
    assert not out.exists()


@pytest.mark.parametrize("walk", WALKS[:-1])
def test_swapped_heels_stop_the_events_step_on_every_clinical_walk(walk, tmp_path):
    path = DATA / walk
    with pytest.raises(LoperInputError, match=r"events.foot_markers \(--feet\) left RHEE, right LHEE: the heel given"):
        events(path, tmp_path / "e.tsv", EventSettings(foot_markers={"left": "RHEE", "right": "LHEE"}))
    assert not (tmp_path / "e.tsv").exists()
