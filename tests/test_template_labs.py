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
from loper_analysis.layout import fill
from loper_analysis.stages import study_paths
from tests.rajagopal_lab import DATA, opensim_ik_reference
from tests.workflow_copy import ROOT, copy_workflow, snakemake

PATHS = study_paths()

pytestmark = pytest.mark.slow  # Snakemake and OpenSim on whole trials
WALK_TRC = DATA / "Rajagopal_motion_capture_walk.trc"


def inspect_and_run(work: Path, subject: str, sheet_row: str, columns: str = "subject\tsource") -> str:
    """A subject's raw files in ``work`` through ``loper-analysis inspect`` (no model: a template) and the workflow,
    with nothing added but the sheet (``columns`` and ``sheet_row``) and the keys ``subjects`` and
    ``device.subject: null``; returns what inspect printed."""
    res = subprocess.run(
        [str(Path(sys.executable).parent / "loper-analysis"), "inspect", f"data/raw/{subject}/static.c3d",
         f"data/raw/{subject}/walk-nodevice.c3d", "--config-out", f"lab/{subject}/config.yaml"],
        cwd=work, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    (work / "lab/subjects.tsv").write_text(f"{columns}\n{sheet_row}\n")
    with (work / f"lab/{subject}/config.yaml").open("a") as fh:
        fh.write("subjects: lab/subjects.tsv\ndevice: {subject: null}\n")
    run = snakemake(work, "--configfile", f"lab/{subject}/config.yaml")
    assert run.returncode == 0, run.stderr[-3000:]
    return res.stdout


@pytest.fixture(scope="module")
def r11(tmp_path_factory):
    """R11's lab files through inspect (no model given) and the workflow, with only the sheet's row and two keys."""
    work = tmp_path_factory.mktemp("r11")
    copy_workflow(work)
    raw = work / "data/raw/R11"
    raw.mkdir(parents=True)
    for trial in ("static", "walk-nodevice"):
        (raw / f"{trial}.c3d").write_bytes((ROOT / f"examples/rajagopal2016/raw/R11/{trial}.c3d").read_bytes())
    return work, inspect_and_run(work, "R11", "R11\trecorded")


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
    report = pd.read_csv(work / fill(PATHS.model.scale, subject="R11"), sep="\t")
    pose = report[report.kind == "pose"].set_index("name").angle_rad
    assert (np.degrees(pose.abs()) < 15).all() and (report.kind == "warning").sum() == 0


def test_hip_knee_and_ankle_agree_with_opensim_s_own_inverse_kinematics(r11, peer):
    work, _ = r11
    ours = pd.read_csv(work / fill(PATHS.ik.angles, subject="R11", trial="walk-nodevice"), sep="\t")
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


QCMAS = ROOT / "tests" / "data" / "c3d-parser" / "QCMAS"


def _clinical_run(work: Path, kad: bool) -> Path:
    """The clinical pair, its static trial written again with markers only (no plates: the sheet gives mass and
    height), the knee markers replaced by a knee alignment device when ``kad``; inspect and the workflow."""
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.c3d_writer import write_c3d
    from tests.knee_device import device_markers

    work.mkdir()
    copy_workflow(work)
    raw = work / "data/raw/QCMAS"
    raw.mkdir(parents=True)
    rec = read_c3d(QCMAS / "static.c3d")
    labels, X = list(rec.marker_labels), rec.markers_m
    if kad:
        keep = [i for i, n in enumerate(labels) if n not in ("LKNE", "RKNE")]
        extra_labels, extra = [], []
        for side, seed in (("L", 1), ("R", 2)):
            knee, medial = X[:, labels.index(f"{side}KNE")], X[:, labels.index(f"{side}MKNE")]
            for code, marker in zip(("KAX", "KD1", "KD2"), device_markers(knee, medial, seed)):
                extra_labels.append(f"{side}{code}")
                extra.append(marker)
        labels, X = [labels[i] for i in keep] + extra_labels, np.concatenate([X[:, keep], np.stack(extra, 1)], 1)
    write_c3d(raw / "static.c3d", labels, X, rec.point_rate_hz, first_frame=rec.first_frame)
    (raw / "walk-nodevice.c3d").write_bytes((QCMAS / "walk-nodevice.c3d").read_bytes())
    printed = inspect_and_run(work, "QCMAS", "QCMAS\trecorded\t1.86\t70.23", "subject\tsource\theight_m\tmass_kg")
    assert "chosen: plugin_gait" in printed
    return work


def test_a_knee_alignment_device_gives_the_model_and_angles_of_the_knee_marker(tmp_path):
    """The same static trial with its knee markers, and with a knee alignment device built around them instead:
    the same scale factors, static pose and walking angles."""
    plain = _clinical_run(tmp_path / "plain", kad=False)
    device = _clinical_run(tmp_path / "kad", kad=True)
    a = pd.read_csv(plain / fill(PATHS.model.scale, subject="QCMAS"), sep="\t")
    b = pd.read_csv(device / fill(PATHS.model.scale, subject="QCMAS"), sep="\t")
    factors = [t[t.kind == "body"].set_index("name").scale_factor_x for t in (a, b)]
    np.testing.assert_allclose(factors[1], factors[0], rtol=1e-4)
    poses = [t[t.kind == "pose"].set_index("name").angle_rad for t in (a, b)]
    np.testing.assert_allclose(poses[1], poses[0], atol=np.radians(0.05))
    angles = [
        pd.read_csv(w / fill(PATHS.ik.angles, subject="QCMAS", trial="walk-nodevice"), sep="\t")
        for w in (plain, device)
    ]
    for column in ("hip_left_rad", "knee_left_rad", "ankle_left_rad", "knee_right_rad"):
        np.testing.assert_allclose(angles[1][column], angles[0][column], atol=np.radians(0.05))
    markers = pd.read_csv(device / fill(PATHS.markers.summary, subject="QCMAS", trial="static"), sep="\t")
    markers = markers.set_index("marker")
    assert markers.loc["LKNE", "label"] == "LKNE (knee alignment device)"


def test_a_qtm_lab_with_its_own_labels_gets_its_known_angles_back(tmp_path):
    """A simulated Qualisys lab (gait2392 driven by known coordinates, markers under QTM-style labels with a subject
    prefix, gaps, belt plates): inspect chooses the ISB template, and the workflow gives the hip, knee and ankle
    angles the files were made from."""
    from tests.lab_export_session import LabExportFiles, LabExportSettings, lab_export_session

    work = tmp_path / "qtm"
    work.mkdir()
    copy_workflow(work)
    example = ROOT / "examples" / "gait2392"
    files = LabExportFiles(
        work / "data/raw/Q01", example / "gait2392_simbody.osim", example / "gait2392_Scale_MarkerSet.xml",
        example / "qtm_label_map.tsv",
    )  # fmt: skip
    settings = LabExportSettings(seed=3, walking_duration_s=15.0)
    truth = lab_export_session(files, "Q01", ["walk-nodevice"], 1.80, 75.1646, settings)
    printed = inspect_and_run(work, "Q01", "Q01\trecorded\t75.1646", "subject\tsource\tmass_kg")
    assert "chosen: isb" in printed and "label map: none needed" in printed  # the labels are the template's
    ours = pd.read_csv(work / fill(PATHS.ik.angles, subject="Q01", trial="walk-nodevice"), sep="\t")
    known = truth["walk-nodevice"][1].coordinates
    np.testing.assert_allclose(ours["time_s"], known["time_s"], atol=1e-9)
    for side, s in (("left", "l"), ("right", "r")):
        for joint, coordinate, sign in (
            ("hip", "hip_flexion", 1),
            ("knee", "knee_angle", -1),
            ("ankle", "ankle_angle", 1),
        ):
            error = np.degrees(ours[f"{joint}_{side}_rad"] - sign * known[f"{coordinate}_{s}"])
            rms = float(np.sqrt(np.nanmean(error**2)))
            assert rms < 0.5, (joint, side, rms)  # measured 0.08-0.16 deg
