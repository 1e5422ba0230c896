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

from loper_analysis.layout import fill
from loper_analysis.stages import study_paths
from tests.browser import report_screen
from tests.workflow_copy import copy_workflow

PATHS = study_paths()

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
    assert config["ik"]["coordinate_map"]["knee_left"] == {"coordinate": "knee_angle_l", "sign": -1}
    assert config["ik"]["coordinate_map"]["pelvis_angle"] == {"coordinate": "pelvis_tilt", "sign": -1}
    assert config["events"]["foot_markers"] == {"left": "LHEE", "right": "RHEE"}
    assert config["markers"] == {"lab_to_model_rotation_deg": [-90, 0, 0], "label_map": {}, "filter": {"cutoff_hz": 40}}
    tasks = pd.read_csv(lab / "ik_tasks.tsv", sep="\t")
    assert "LMKNE" not in set(tasks["name"]) and {"LKNE", "LTHI", "LTOE"} <= set(tasks["name"])
    # the generic model is OpenSim's gait2392 as distributed
    assert (lab / "gait2392_simbody.osim").read_bytes() == (
        ROOT / "src/loper_analysis/templates/gait2392_simbody.osim"
    ).read_bytes()


#: Tolerances of the figures the doc quotes, each the accuracy of the method that computes it, not its last digit:
#: scale factors are ratios of distances between markers and regression centres (arithmetic: 0.002); marker errors
#: and joint angles come from OpenSim's IK solves (accuracy 1e-5 on a weighted sum of squares; 1 mm, 0.5 degree);
#: correlations 0.005; event times one analog sample either way of the 50 N crossing (2 ms).
SCALE_TOL, MM_TOL, DEG_TOL, R_TOL, EVENT_TOL_S = 0.002, 1.0, 0.5, 0.005, 0.002


def _deg(values) -> np.ndarray:
    return np.degrees(np.asarray(values, float))


def test_the_scale_report_and_the_hand_run_agree_with_the_doc(walkthrough):
    work, _ = walkthrough
    report = pd.read_csv(work / fill(PATHS.model.scale, subject="QCMAS"), sep="\t")
    by_hand = pd.read_csv(work / "lab/QCMAS_scale.tsv", sep="\t")
    pd.testing.assert_frame_equal(report, by_hand)  # the same code on the same files: the same bytes
    subject = report[report.kind == "subject"].iloc[0]
    assert subject.mass_kg == pytest.approx(72.2, abs=0.05) and subject.height_m == 1.86
    assert "force plate" in subject.source and "PROCESSING:Height" in subject.source
    bodies = report[report.kind == "body"].set_index("name").scale_factor_x
    np.testing.assert_allclose(
        [bodies[b] for b in ("pelvis", "femur_r", "tibia_r", "calcn_r", "torso")],
        [1.073, 1.109, 1.004, 0.996, 0.996],
        atol=SCALE_TOL,
    )
    centres = report[report.kind == "joint_centre"].set_index("name").source
    assert centres["LHJC"].startswith("Plug-in Gait's regression (Davis et al. 1991) on the lab's leg lengths 970")
    assert centres["LKJC"] == "midpoint of LKNE and LMKNE" and centres["RAJC"] == "midpoint of RANK and RMMAL"
    fits = report[report.kind == "markers"].set_index("name")
    assert 1000 * fits.loc["before placement", "marker_error_rms_m"] == pytest.approx(33.2, abs=MM_TOL)
    assert 1000 * fits.loc["before placement", "marker_error_max_m"] == pytest.approx(83.7, abs=MM_TOL)
    assert fits.loc["before placement", "worst_marker"] == "LTHI"
    assert 1000 * fits.loc["after placement", "marker_error_rms_m"] == pytest.approx(4.9, abs=MM_TOL)
    pose = report[report.kind == "pose"].set_index("name")
    keys = ["hip_left", "hip_right", "knee_left", "knee_right", "ankle_left", "ankle_right"]
    ours, lab = _deg(pose.angle_rad[keys]), _deg(pose.lab_angle_rad[keys])
    np.testing.assert_allclose(ours, [-0.3, 0.1, -7.9, -11.1, -1.0, -4.9], atol=DEG_TOL)
    np.testing.assert_allclose(lab, [0.0, 1.1, -8.1, -10.8, 0.4, -4.0], atol=0.05)  # the file's own numbers
    # the calibration's answer against the lab's own model: hip and knee within 1.5 degrees, the ankle within 1.5
    assert np.all(np.abs(ours - lab)[:4] < 1.5) and np.all(np.abs(ours - lab)[4:] < 1.5)
    assert (report.kind == "warning").sum() == 0


def test_ik_events_and_the_summary_say_what_the_doc_says(walkthrough):
    work, _ = walkthrough
    static = pd.read_csv(work / fill(PATHS.markers.summary, subject="QCMAS", trial="static"), sep="\t").iloc[0]
    assert static.turn_deg == 90.0
    ik = pd.read_csv(work / fill(PATHS.ik.summary, subject="QCMAS", trial="walk-nodevice"), sep="\t").iloc[0]
    assert (ik.n_frames, ik.n_frames_solved, ik.n_frames_left_out) == (216, 216, 0)
    assert 1000 * ik.marker_rms_mean_m == pytest.approx(8.3, abs=MM_TOL) and ik.worst_marker == "LTHI"
    worst = dict(item.split() for item in ik.worst_markers_mm.split(", "))
    assert list(worst)[0] == "LTHI" and float(worst["LTHI"]) == pytest.approx(17.2, abs=MM_TOL)
    agree = pd.read_csv(work / fill(PATHS.ik.agreement, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    agree = agree.set_index("angle").loc[
        ["hip_left", "hip_right", "knee_left", "knee_right", "ankle_left", "ankle_right"]
    ]
    np.testing.assert_allclose(agree.r, [0.991, 0.995, 0.994, 0.994, 0.981, 0.982], atol=R_TOL)
    np.testing.assert_allclose(_deg(agree.rms_diff_rad), [4.0, 3.4, 5.5, 3.6, 4.0, 2.7], atol=DEG_TOL)
    events = pd.read_csv(work / fill(PATHS.events.events, subject="QCMAS", trial="walk-nodevice"), sep="\t")
    hs = events[events.event == "heel_strike"].time_s.to_numpy()
    to = events[events.event == "toe_off"].time_s.to_numpy()
    np.testing.assert_allclose(hs, [2.461, 3.024, 3.543], atol=EVENT_TOL_S)
    np.testing.assert_allclose(to, [3.183, 3.710, 4.246], atol=EVENT_TOL_S)
    summary = pd.read_csv(work / PATHS.strides.summary, sep="\t").iloc[0]
    assert (summary.subject, summary.status, summary.n_strides, summary.turn_deg) == (
        "QCMAS", "too_few_strides", 1, 270.0,
    )  # fmt: skip
    assert summary.speed_m_per_s == pytest.approx(1.27, abs=0.005)
    assert summary.lab_joints_min_r == pytest.approx(0.981, abs=R_TOL)
    assert np.degrees(summary.lab_joints_max_rms_diff_rad) == pytest.approx(5.5, abs=DEG_TOL)
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
    assert "mass 72.2 kg, height 1.86 m" in measured["text"]
    assert re.search(r"before placement 3[234]\.\d 8[2-5]\.\d LTHI", measured["text"])  # 33.2, 83.7 mm (1 mm)


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
