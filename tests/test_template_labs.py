"""Other labs' files through ``inspect`` and the workflow with a marker-set template, checked against an answer we
did not compute: OpenSim's Rajagopal2016 walking subject, written as a Vicon lab's C3D files (``R.ASIS``,
``R.Knee``, thigh clusters), chooses the Qualisys/ISB template on gait2392; its joint angles are compared with
OpenSim's own InverseKinematicsTool on Rajagopal2016 with the lab's IK setup (another model: a few degrees of
offset are expected, the shapes must agree)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.io.osim import quiet_opensim, read_model
from tests.rajagopal_lab import DATA, opensim_ik_reference
from tests.workflow_copy import ROOT, copy_workflow, snakemake

pytestmark = pytest.mark.slow  # Snakemake and OpenSim on whole trials
WALK_TRC = DATA / "Rajagopal_motion_capture_walk.trc"


@pytest.fixture(scope="module")
def r11(tmp_path_factory):
    """R11's lab files through inspect (no model given) and the workflow, with only the sheet's row and two keys."""
    work = tmp_path_factory.mktemp("r11")
    copy_workflow(work)
    raw = work / "data/raw/R11"
    raw.mkdir(parents=True)
    for trial in ("static", "walk-nodevice"):
        (raw / f"{trial}.c3d").write_bytes((ROOT / f"examples/rajagopal2016/raw/R11/{trial}.c3d").read_bytes())
    res = subprocess.run(
        [str(Path(sys.executable).parent / "loper-analysis"), "inspect", "data/raw/R11/static.c3d",
         "data/raw/R11/walk-nodevice.c3d", "--config-out", "lab/R11/config.yaml"],
        cwd=work, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    (work / "lab/subjects.tsv").write_text("subject\tsource\nR11\trecorded\n")
    with (work / "lab/R11/config.yaml").open("a") as fh:
        fh.write("subjects: lab/subjects.tsv\ndevice: {subject: null}\n")
    run = snakemake(work, "--configfile", "lab/R11/config.yaml")
    assert run.returncode == 0, run.stderr[-3000:]
    return work, res.stdout


@pytest.fixture(scope="module")
def peer(tmp_path_factory):
    """OpenSim's InverseKinematicsTool: Rajagopal2016 with the lab's marker set and IK setup, on the walking TRC."""
    d = tmp_path_factory.mktemp("peer")
    osim = quiet_opensim()
    model = read_model(DATA / "Rajagopal2016.osim")
    model.updateMarkerSet(osim.MarkerSet(str(DATA / "Rajagopal_markerset_walk_preScale.xml")))
    model.printToXML(str(d / "model.osim"))
    return opensim_ik_reference(d / "model.osim", DATA / "Rajagopal_ik_setup_walk.xml", WALK_TRC, d / "peer.mot")


def test_the_isb_template_is_chosen_and_the_static_pose_is_upright(r11):
    work, printed = r11
    assert "chosen: isb" in printed and "isb          12 of 12 required" in printed
    report = pd.read_csv(work / "results/model/R11/scale.tsv", sep="\t")
    pose = report[report.kind == "pose"].set_index("name").angle_rad
    assert (np.degrees(pose.abs()) < 15).all() and (report.kind == "warning").sum() == 0


def test_hip_knee_and_ankle_agree_with_opensim_s_own_inverse_kinematics(r11, peer):
    work, _ = r11
    ours = pd.read_csv(work / "results/ik/R11/walk-nodevice.angles.tsv", sep="\t")
    assert len(ours) == len(peer) == 238
    np.testing.assert_allclose(ours["time_s"], peer["time_s"], atol=1e-9)
    for side, s in (("left", "l"), ("right", "r")):
        for joint, coordinate, r_min, rms_max in (
            ("hip", "hip_flexion", 0.95, 8.0), ("knee", "knee_angle", 0.95, 8.0), ("ankle", "ankle_angle", 0.8, 10.0)
        ):  # fmt: skip
            a = np.degrees(ours[f"{joint}_{side}_rad"].to_numpy())
            b = np.degrees(peer[f"{coordinate}_{s}"].to_numpy())  # Rajagopal2016: flexion positive
            r, rms = np.corrcoef(a, b)[0, 1], np.sqrt(np.mean((a - b) ** 2))
            assert r >= r_min and rms <= rms_max, (joint, side, r, rms)
