"""Frames stored in reverse time are warned about by the events step: on the real walks (the seven clinical labs',
OpenSim's walking5) and the synthetic lab's treadmill walk on belt plates, each as stored and with its frames
(markers and analogs) flipped, written with the project's C3D writer: the figure the rule reads, measured per
file, and the warning or its absence.
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from pathlib import Path

import ezc3d
import numpy as np
import pandas as pd
import pytest

from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import ForcePlatform, write_recording
from loper_analysis.motion.label_matching import heel_markers
from loper_analysis.stages.events.step import EventSettings, events

DATA = Path(__file__).resolve().parents[1] / "data"
LABS = ("AUC", "FMC", "MH", "QCMAS", "RBWH", "RCH", "SYD")
WALKS = [f"c3d-parser/{lab}/walk-nodevice.c3d" for lab in LABS] + ["opensim-core/walking5.c3d"]

#: Median over a walk's foot contacts of the heel's rise minus the toe's at the contact's end (mm), forward and
#: with the frames reversed (None: no contact of one foot once reversed, hence no events; RCH, the toe walker,
#: lands toe first: reversed, its contacts end as they began, and the rule cannot tell).
TOE_OFF_HEEL_LEAD_MM = {
    "c3d-parser/AUC/walk-nodevice.c3d": (126, -7),
    "c3d-parser/FMC/walk-nodevice.c3d": (136, -30),
    "c3d-parser/MH/walk-nodevice.c3d": (102, None),
    "c3d-parser/QCMAS/walk-nodevice.c3d": (175, -56),
    "c3d-parser/RBWH/walk-nodevice.c3d": (135, -30),
    "c3d-parser/RCH/walk-nodevice.c3d": (88, 0),
    "c3d-parser/SYD/walk-nodevice.c3d": (151, -48),
    "opensim-core/walking5.c3d": (209, -59),
}


def _platforms(path: Path) -> list[ForcePlatform]:
    """The file's FORCE_PLATFORM group as the writer takes it (m)."""
    c = ezc3d.c3d(str(path))
    fp = c["parameters"]["FORCE_PLATFORM"]
    unit = {"mm": 1e-3, "cm": 1e-2, "m": 1.0}[c["parameters"]["POINT"]["UNITS"]["value"][0].strip()]
    out = []
    for k in range(int(fp["USED"]["value"][0])):
        kind = int(fp["TYPE"]["value"][k])
        cal = tuple(map(tuple, np.asarray(fp["CAL_MATRIX"]["value"])[:, :, k])) if kind == 4 else None
        out.append(
            ForcePlatform(
                kind,
                tuple(map(tuple, np.asarray(fp["CORNERS"]["value"])[:, :, k].T * unit)),
                tuple(np.asarray(fp["ORIGIN"]["value"])[:, k] * unit),
                tuple(int(v) for v in np.asarray(fp["CHANNEL"]["value"])[:, k]),
                cal,
            )
        )
    return out


def _reversed(path: Path, out: Path) -> Path:
    """The file with its frames in reverse order (markers and analogs), written with the project's writer."""
    rec = read_c3d(path)
    flipped = dataclasses.replace(rec, markers_m=rec.markers_m[::-1].copy(), analogs=rec.analogs[::-1].copy())
    return write_recording(out, flipped, force_platforms=_platforms(path))


def _settings(path: Path) -> EventSettings:
    return EventSettings(foot_markers=heel_markers([label.split(":")[-1] for label in read_c3d(path).marker_labels]))


@pytest.mark.parametrize("walk", WALKS)
def test_a_walk_played_backwards_is_warned_about_and_forward_is_not(walk, tmp_path, caplog):
    caplog.set_level(logging.INFO, logger="loper_analysis.gait.trial_events")
    forward_mm, backward_mm = TOE_OFF_HEEL_LEAD_MM[walk]
    path = DATA / walk
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)  # forward: no warning at all
        events(path, tmp_path / "f.tsv", _settings(path))
    assert f"the heel had risen {forward_mm} mm more than the toe (median)" in caplog.text
    caplog.clear()
    backward = _reversed(path, tmp_path / "reversed.c3d")
    if backward_mm is None:  # both feet on every plate: no contact of one foot, no events to run backwards
        table = events(backward, tmp_path / "b.tsv", _settings(path), contacts_out=tmp_path / "c.tsv")
        assert not table["event"].isin(["heel_strike", "toe_off"]).any()
        assert (pd.read_csv(tmp_path / "c.tsv", sep="\t")["flag"] == "two_feet").all()
        return
    if backward_mm >= 0:  # the toe walker: not told
        with warnings.catch_warnings():
            warnings.simplefilter("error", UserWarning)
            events(backward, tmp_path / "b.tsv", _settings(path))
        assert f"the heel had risen {backward_mm} mm more than the toe (median)" in caplog.text
        return
    with pytest.warns(UserWarning, match="time seems to run backwards in this file") as said:
        events(backward, tmp_path / "b.tsv", _settings(path))
    (message,) = [str(w.message) for w in said if "backwards" in str(w.message)]
    assert message.startswith(f"{backward}: time seems to run backwards in this file: ")
    assert f"(by {-backward_mm} mm, median)" in message


def test_a_treadmill_walk_on_belt_plates_played_backwards_is_warned_about(tmp_path):
    """The synthetic lab's QTM export (two belt plates, ISB labels): 9 of 9 contacts end toe-last reversed."""
    from loper_analysis.io.readers import read_label_map
    from tests.lab_export_session import LabExportFiles, LabExportSettings, lab_export_session

    gait2392 = DATA.parent.parent / "examples" / "gait2392"
    files = LabExportFiles(
        tmp_path,
        gait2392 / "gait2392_simbody.osim",
        gait2392 / "gait2392_Scale_MarkerSet.xml",
        gait2392 / "qtm_label_map.tsv",
    )
    lab_export_session(files, "S01", ["walk-device"], 1.75, 70.0, LabExportSettings(seed=11, walking_duration_s=8.0))
    walk = next(tmp_path.rglob("walk-device.c3d"))
    settings = EventSettings(
        foot_markers={"left": "L.Heel", "right": "R.Heel"}, label_map=read_label_map(files.label_map_tsv)
    )
    assert read_c3d(walk).n_force_platforms == 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        events(walk, tmp_path / "f.tsv", settings)
    backward = _reversed(walk, tmp_path / "reversed.c3d")
    with pytest.warns(UserWarning, match="time seems to run backwards in this file") as said:
        events(backward, tmp_path / "b.tsv", settings)
    (message,) = [str(w.message) for w in said if "backwards" in str(w.message)]
    assert f"{backward}: time seems to run backwards in this file: 9 of its 9 foot contact(s)" in message
