"""The walk-through docs/first_recorded_subject.md: its commands, run as written, and the figures it quotes."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.layout import Paths, fill
from tests.browser import report_screen
from tests.workflow_copy import copy_workflow

PATHS = Paths()

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
        "cp",
        "loper-analysis",
        "printf",
        "printf",
        "loper-analysis",
        "snakemake",
        "snakemake",
        "loper-analysis",
    ]


def test_inspect_chooses_plug_in_gait_and_writes_what_the_doc_says(walkthrough):
    work, outputs = walkthrough
    printed = outputs[2][1]
    assert "plugin_gait  12 of 12 required, 24 of 25 markers" in printed
    assert "isb          10 of 12 required" in printed and "chosen: plugin_gait" in printed
    assert "static trial only (not tracked in walking): LMKNE, RMKNE, LMMAL, RMMAL" in printed
    assert "labels without a template marker (kept, not used): RBAK" in printed and "label map: none needed" in printed
    lab = work / "lab/QCMAS"
    assert sorted(p.name for p in lab.iterdir()) == [
        "config.yaml", "gait2392_simbody.osim", "ik_tasks.tsv", "marker_set.xml", "scale_setup.xml",
    ]  # fmt: skip
    config = yaml.safe_load((lab / "config.yaml").read_text())
    assert config["opensim"]["coordinate_map"]["knee_left"] == {"coordinate": "knee_angle_l", "sign": -1}
    assert config["opensim"]["coordinate_map"]["pelvis_angle"] == {"coordinate": "pelvis_tilt", "sign": -1}
    assert config["events"]["foot_markers"] == {"left": "LHEE", "right": "RHEE"}
    assert config["markers"] == {"lab_to_model_rotation_deg": [-90, 0, 0], "label_map": {}}
    tasks = pd.read_csv(lab / "ik_tasks.tsv", sep="\t")
    assert "LMKNE" not in set(tasks["name"]) and {"LKNE", "LTHI", "LTOE"} <= set(tasks["name"])
    # the generic model is OpenSim's gait2392 as distributed
    assert (lab / "gait2392_simbody.osim").read_bytes() == (
        ROOT / "src/loper_analysis/templates/gait2392_simbody.osim"
    ).read_bytes()


def test_the_scale_report_and_the_hand_run_agree_with_the_doc(walkthrough):
    work, _ = walkthrough
    report = pd.read_csv(work / fill(PATHS.model.scale, subject="QCMAS"), sep="\t")
    by_hand = pd.read_csv(work / "lab/QCMAS_scale.tsv", sep="\t")
    pd.testing.assert_frame_equal(report, by_hand)
    subject = report[report.kind == "subject"].iloc[0]
    assert round(subject.mass_kg, 1) == 72.2 and subject.height_m == 1.86
    assert "force plates" in subject.source and "PROCESSING:Height" in subject.source
    bodies = report[report.kind == "body"].set_index("name").scale_factor_x.round(3).to_dict()
    assert [bodies[b] for b in ("pelvis", "femur_r", "tibia_r", "calcn_r", "torso")] == [
        1.058,
        1.071,
        1.108,
        0.995,
        0.993,
    ]
    fits = report[report.kind == "markers"].set_index("name")
    assert round(1000 * fits.loc["before placement", "marker_error_rms_m"], 1) == 37.0
    assert round(1000 * fits.loc["before placement", "marker_error_max_m"], 1) == 97.9
    assert fits.loc["before placement", "worst_marker"] == "LTHI"
    assert round(1000 * fits.loc["after placement", "marker_error_rms_m"], 1) == 13.1
    pose = report[report.kind == "pose"].set_index("name")
    ours = {k: round(float(np.degrees(v)), 1) for k, v in pose.angle_rad.items()}
    lab = {k: round(float(np.degrees(v)), 1) for k, v in pose.lab_angle_rad.items()}
    assert [ours[k] for k in ("hip_left", "hip_right", "knee_left", "knee_right", "ankle_left", "ankle_right")] == [
        4.7,
        4.8,
        -4.0,
        -8.1,
        1.4,
        -2.4,
    ]
    assert [lab[k] for k in ("hip_left", "hip_right", "knee_left", "knee_right", "ankle_left", "ankle_right")] == [
        0.1,
        1.1,
        -8.1,
        -10.8,
        0.3,
        -4.1,
    ]
    assert (report.kind == "warning").sum() == 0


def test_ik_events_and_the_summary_say_what_the_doc_says(walkthrough):
    work, _ = walkthrough
    static = pd.read_csv(work / fill(PATHS.markers.summary, subject="QCMAS", trial="static"), sep="\t").iloc[0]
    assert static.turn_deg == 90.0
    ik = pd.read_csv(work / fill(PATHS.ik.summary, subject="QCMAS", trial="walk-nodevice"), sep="\t").iloc[0]
    assert (ik.n_frames, ik.n_frames_solved, ik.n_frames_left_out) == (216, 216, 0)
    assert round(1000 * ik.marker_rms_mean_m, 1) == 15.8 and ik.worst_marker == "LTHI"
    assert ik.worst_markers_mm == "LTHI 27.8, LKNE 24.3, RTHI 22.0"
    agree = pd.read_csv(work / fill(PATHS.ik.agreement, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    agree = agree.set_index("angle")
    figures = {
        a: (round(agree.loc[a, "r"], 3), round(float(np.degrees(agree.loc[a, "rms_diff_rad"])), 1))
        for a in ("hip_left", "hip_right", "knee_left", "knee_right", "ankle_left", "ankle_right")
    }
    assert figures == {
        "hip_left": (0.991, 2.5), "hip_right": (0.994, 3.1), "knee_left": (0.998, 4.1),
        "knee_right": (0.997, 4.5), "ankle_left": (0.98, 1.8), "ankle_right": (0.985, 1.3),
    }  # fmt: skip
    events = pd.read_csv(work / fill(PATHS.events.events, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    hs = events[events.event == "heel_strike"].time_s.round(3).tolist()
    to = events[events.event == "toe_off"].time_s.round(3).tolist()
    assert hs == [2.461, 3.024, 3.543] and to == [3.183, 3.71, 4.246]
    summary = pd.read_csv(work / PATHS.strides.summary, sep="\t").iloc[0]
    assert (summary.subject, summary.status, summary.n_strides, summary.turn_deg) == (
        "QCMAS", "too_few_strides", 1, 270.0,
    )  # fmt: skip
    assert round(summary.speed_m_per_s, 2) == 1.27
    assert (
        round(summary.lab_joints_min_r, 3) == 0.98 and round(np.degrees(summary.lab_joints_max_rms_diff_rad), 1) == 4.5
    )
    assert not (work / PATHS.validation.root).exists() and not (work / PATHS.impedance.root).exists()


def test_the_report_shows_the_subject_in_a_browser(walkthrough, tmp_path):
    """The report's front page, opened in headless Chromium: the recorded subject's section and the table of its
    trials are drawn, both figures decode, and the numbers are the tables'."""
    work, _ = walkthrough
    html = (work / PATHS.results_dir / "report.html").read_text(errors="replace")
    assert len(html) > 100_000 and "QCMAS" in html
    screen = report_screen()
    if screen.chromium_path() is None:
        pytest.skip("no Chromium at /usr/bin/chromium (or $CHROMIUM): the report cannot be rendered")
    measured = screen.first_screen(
        work / PATHS.results_dir / "report.html", tmp_path / "screen.png", ready_id="lf-trials"
    )
    boxes = measured["boxes"]
    assert boxes["lf-recorded"]["top"] < 900 and boxes["lf-trials"]["bottom"] > boxes["lf-trials"]["top"]
    assert sorted(alt for alt, width, height in measured["images"] if width > 0 and height > 0) == [
        "QCMAS walk-nodevice: force plates and events",
        "QCMAS walk-nodevice: joint angles over the gait cycle",
    ]
    assert "mass 72.2 kg, height 1.86 m" in measured["text"] and "before placement 37.0 97.9 LTHI" in measured["text"]


def test_every_clean_plate_contact_has_its_events_within_15_ms_of_the_plate_s_own_contact(walkthrough):
    """Against the plates themselves: each contact the events step calls clean (flag ``ok``) starts and ends where
    its plate's vertical force crosses 20 N above the plate's resting level, within 15 ms."""
    from loper_analysis.io.force_platforms import read_force_platforms

    work, _ = walkthrough
    contacts = pd.read_csv(work / fill(PATHS.events.contacts, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    events = pd.read_csv(work / fill(PATHS.events.events, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    plates = {p.number: p for p in read_force_platforms(ROOT / "tests/data/c3d-parser/QCMAS/walk-nodevice.c3d")}
    clean = contacts[contacts.flag == "ok"]
    assert len(clean) == 3
    for row in clean.itertuples():
        plate = plates[row.plate]
        fz, t = plate.force_n[:, 2], plate.time_s
        rest = np.median(fz[fz < fz.min() + 10.0])
        loaded = np.flatnonzero(fz - rest > 20.0)
        on, off = t[loaded[0]], t[loaded[-1]]
        mine = events[events.side == row.side]
        hs = mine[mine.event == "heel_strike"].time_s.to_numpy()
        to = mine[mine.event == "toe_off"].time_s.to_numpy()
        assert np.min(np.abs(hs - on)) <= 0.015 and np.min(np.abs(to - off)) <= 0.015, (row.plate, on, off)
