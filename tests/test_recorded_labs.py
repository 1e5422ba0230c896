"""Recorded subjects from other labs through the workflow, with OpenSim's models as distributed.

* ``R11``: OpenSim's Rajagopal2016 walking subject as a Vicon lab's C3D files (``tests/rajagopal_lab.py``: markers
  in mm, Z up, a plate under each stance of an overground walkway, a static trial standing on two plates), with
  Rajagopal2016.osim, the lab's ScaleTool setup and its IK setup (``examples/rajagopal2016/config.yaml``); no
  height, no mass (from the static plates), no device trials. The scaled model must be OpenSim's ScaleTool's,
  the joint angles OpenSim's InverseKinematicsTool's and the events the plate contacts.
* ``W05``: OpenSim's own ``walking5.c3d`` (Vicon Nexus, overground, walking toward -X, no marker in the first
  57 frames) with Rajagopal2016.osim as the subject's model: frames without markers left out, the trial turned
  to walk along +X, the angles of a walking person, one stride short of a stride: ``too_few_strides``.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.io.opensim_tables import read_markers, read_mot, write_trc
from loper_analysis.io.osim import read_model
from loper_analysis.layout import fill
from loper_analysis.motion.markers import rotate_markers
from loper_analysis.stages import study_paths
from loper_analysis.stages.markers.step import MarkerSettings
from tests.rajagopal_lab import (
    GENERIC_OSIM,
    GRF_MOT,
    IK_SETUP,
    MARKER_SET,
    SCALE_SETUP,
    STATIC_TRC,
    SUBJECT_MASS_KG,
    WALK_TRC,
    opensim_ik_reference,
    opensim_scale_reference,
    write_lab_files,
)
from tests.workflow_copy import copy_workflow, snakemake

PATHS = study_paths()

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials (pytest -m "not slow" leaves them out)
ROOT = Path(__file__).resolve().parents[1]
WALKING5 = ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
#: Coordinates the study reads and those that carry them (the arms' are left to their markers' whims, below).
BODY_COORDINATES = (
    "pelvis_tilt",
    "pelvis_list",
    "pelvis_rotation",
    "pelvis_tx",
    "pelvis_ty",
    "pelvis_tz",
    "hip_flexion_r",
    "hip_adduction_r",
    "hip_rotation_r",
    "knee_angle_r",
    "ankle_angle_r",
    "hip_flexion_l",
    "hip_adduction_l",
    "hip_rotation_l",
    "knee_angle_l",
    "ankle_angle_l",
    "lumbar_extension",
    "lumbar_bending",
    "lumbar_rotation",
)


def _workflow(tmp_path_factory, name: str, subjects: str, overrides: dict) -> Path:
    work = tmp_path_factory.mktemp(name)
    copy_workflow(work)
    (work / "config/subjects.tsv").write_text(subjects)
    (work / "config/test.yaml").write_text(yaml.safe_dump({"subjects": "config/subjects.tsv", **overrides}))
    return work


def _run(work: Path, targets: list[str]) -> subprocess.CompletedProcess:
    return snakemake(work, *targets, "--configfile", "examples/rajagopal2016/config.yaml", "config/test.yaml")


@pytest.fixture(scope="module")
def rajagopal(tmp_path_factory):
    """R11 through the workflow; the lab files' static trial complete (as OpenSim's pipeline has it)."""
    work = _workflow(tmp_path_factory, "rajagopal", "subject\tsource\nR11\trecorded\n", {})
    write_lab_files(work / "data/raw/R11", static_gaps={})
    res = _run(
        work,
        [
            PATHS.strides.summary,
            fill(PATHS.model.scale, subject="R11"),
            fill(PATHS.grf.mot, subject="R11", trial="walk-nodevice"),
            fill(PATHS.model.segments, subject="R11"),
        ],
    )
    assert res.returncode == 0, res.stderr[-3000:]
    return work


def test_scaled_model_is_opensims_scale_tool(rajagopal, tmp_path):
    ours = read_model(rajagopal / fill(PATHS.model.scaled, subject="R11"))
    # the workflow turned the static trial about the vertical to face +X (its pelvis markers): the same turn of
    # OpenSim's own static trial
    turn = pd.read_csv(rajagopal / fill(PATHS.markers.summary, subject="R11", trial="static"), sep="\t")
    turn = turn.turn_deg.iloc[0]
    assert turn == 90.0
    t, X, labels = read_markers(STATIC_TRC)
    write_trc(tmp_path / "static.trc", t, rotate_markers(X, (0.0, turn, 0.0)), labels)
    # OpenSim's ScaleTool with the setup as distributed, its pipeline's marker set and the mass the plates carry
    peer = read_model(
        opensim_scale_reference(
            GENERIC_OSIM, SCALE_SETUP, tmp_path / "static.trc", SUBJECT_MASS_KG, tmp_path / "peer.osim",
            marker_set_xml=MARKER_SET,
        )
    )  # fmt: skip
    s1, s2 = ours.initSystem(), peer.initSystem()
    # the mass comes from the plates' float32 channels: 85.0668003 kg (3e-9 relative)
    assert ours.getTotalMass(s1) == pytest.approx(peer.getTotalMass(s2), rel=1e-8)
    for i in range(peer.getBodySet().getSize()):
        b2 = peer.getBodySet().get(i)
        b1 = ours.getBodySet().get(b2.getName())
        assert b1.getMass() == pytest.approx(b2.getMass(), rel=1e-8)
        np.testing.assert_allclose(
            b1.getInertia().getMoments().to_numpy(), b2.getInertia().getMoments().to_numpy(), rtol=1e-8
        )
    m1, m2 = ours.getMarkerSet(), peer.getMarkerSet()
    assert m1.getSize() == m2.getSize() == 41
    for i in range(m2.getSize()):
        theirs = m2.get(i).get_location().to_numpy()
        mine = m1.get(m2.get(i).getName()).get_location().to_numpy()
        # the static trial reaches ScaleTool as recorded, through float32 in the C3D: measured at most 4.5 µm
        assert np.linalg.norm(mine - theirs) < 1e-4 * np.linalg.norm(theirs), m2.get(i).getName()


def test_scale_report_gives_the_mass_from_the_plates(rajagopal):
    report = pd.read_csv(rajagopal / fill(PATHS.model.scale, subject="R11"), sep="\t")
    subject = report[report.kind == "subject"].iloc[0]
    assert subject.mass_kg == pytest.approx(SUBJECT_MASS_KG, rel=1e-6)  # weight / Rajagopal2016's 9.80665 m/s²
    assert "force plates 1, 2 of static.c3d" in subject.source and "estimated" in subject.source
    assert 1.5 < subject.height_m < 1.9
    bodies = report[report.kind == "body"]
    assert len(bodies) == 22 and (bodies[["scale_factor_x", "scale_factor_y", "scale_factor_z"]] == 1.0).all().all()
    markers = report[report.kind == "marker"]
    assert len(markers) == 23  # the marker placer's weighted tasks
    assert markers.label.str.startswith("Subject11:").all()  # the lab's labels
    overall = report[report.kind == "markers"].set_index("name").loc["after placement"]
    assert 0.03 < overall.marker_error_rms_m < 0.07  # an unscaled generic model on this subject


def test_angles_are_opensims_inverse_kinematics_tool(rajagopal, tmp_path):
    # the lab's IK setup at the pipeline's accuracy (1e-6): at its own (1e-5) OpenSim's result moves by 0.13-0.30 deg
    # RMS from the converged one (1e-8) on this unscaled model, whose marker errors leave the optimum flat; at 1e-6
    # by at most 0.03 deg
    setup = tmp_path / "ik_setup.xml"
    setup.write_text(IK_SETUP.read_text().replace("<accuracy>1e-05</accuracy>", "<accuracy>1e-06</accuracy>"))
    peer = opensim_ik_reference(
        rajagopal / fill(PATHS.model.scaled, subject="R11"), setup, WALK_TRC, tmp_path / "peer.mot"
    )
    ours = read_mot(rajagopal / fill(PATHS.ik.mot, subject="R11", trial="walk-nodevice"))
    assert len(ours) == len(peer) == 238
    np.testing.assert_allclose(ours["time_s"], peer["time_s"], atol=1e-9)
    for name in BODY_COORDINATES:
        scale = 1.0 if name.endswith(("_tx", "_ty", "_tz")) else np.degrees(1.0)  # deg, or m
        rms = np.sqrt(np.mean((scale * (ours[name] - peer[name])) ** 2))
        assert rms < (0.1 if scale != 1.0 else 2e-4), (name, rms)
    angles = pd.read_csv(rajagopal / fill(PATHS.ik.angles, subject="R11", trial="walk-nodevice"), sep="\t")
    np.testing.assert_allclose(angles["knee_left_rad"], ours["knee_angle_l"], rtol=0, atol=1e-8)  # flexion positive


def test_events_are_the_plate_contacts(rajagopal):
    mot = read_mot(GRF_MOT)
    events = pd.read_csv(rajagopal / fill(PATHS.events.events, subject="R11", trial="walk-nodevice"), sep="\t")
    for side, s in (("right", "r"), ("left", "l")):
        t, fz = mot["time_s"].to_numpy(), mot[f"ground_force_{s}_vy"].to_numpy()
        strikes = t[1:][(fz[1:] >= 50.0) & (fz[:-1] < 50.0)]
        offs = t[1:][(fz[1:] < 20.0) & (fz[:-1] >= 20.0)]
        for kind, expected in (("heel_strike", strikes), ("toe_off", offs)):
            ours = events[(events.side == side) & (events.event == kind)]["time_s"].to_numpy()
            assert len(ours) == len(expected) > 0, (side, kind)
            assert np.abs(ours - expected).max() <= 1 / 2000 + 1e-9, (side, kind)  # within one analog sample
    contacts = pd.read_csv(rajagopal / fill(PATHS.events.contacts, subject="R11", trial="walk-nodevice"), sep="\t")
    assert contacts["flag"].tolist() == ["ok"] * 3 and contacts["side"].tolist() == ["right", "left", "right"]


def test_the_trial_summary_flags_the_stride_short_trial(rajagopal):
    summary = pd.read_csv(rajagopal / PATHS.strides.summary, sep="\t")
    row = summary.iloc[0]
    assert (row.subject, row.trial, row.n_strides, row.status) == ("R11", "walk-nodevice", 0, "too_few_strides")
    assert (row.n_frames, row.n_frames_left_out, row.turn_deg) == (238, 0, 0.0)  # walks +X already
    assert row.heading_deg == pytest.approx(0.0, abs=5.0) or row.heading_deg == pytest.approx(360.0, abs=5.0)


@pytest.fixture(scope="module")
def walking5(tmp_path_factory):
    """W05: walking5.c3d as a recorded subject's walking trial, Rajagopal2016.osim as its model."""
    work = _workflow(
        tmp_path_factory,
        "walking5",
        "subject\tsource\tmodel_osim\nW05\trecorded\texamples/rajagopal2016/Rajagopal2016.osim\n",
        {
            "opensim": {"ik_tasks": "examples/rajagopal2016/lower_body_ik_tasks.tsv"},
            "events": {"foot_markers": {"left": "LCAL", "right": "RCAL"}},
        },
    )
    (work / "data/raw/W05").mkdir(parents=True)
    shutil.copy(WALKING5, work / "data/raw/W05/walk-nodevice.c3d")
    res = _run(work, [PATHS.strides.summary, fill(PATHS.grf.mot, subject="W05", trial="walk-nodevice")])
    assert res.returncode == 0, res.stderr[-3000:]
    return work


def test_walking5_frames_without_markers_are_left_out(walking5):
    ik = pd.read_csv(walking5 / fill(PATHS.ik.summary, subject="W05", trial="walk-nodevice"), sep="\t").iloc[0]
    markers = pd.read_csv(walking5 / fill(PATHS.markers.summary, subject="W05", trial="walk-nodevice"), sep="\t")
    assert markers["n_frames_too_few_markers"].iloc[0] == 153  # frames 0-134 and 1085-1102 (57 without any)
    assert ik.n_frames == 1103 and ik.n_frames_left_out >= 153  # and those without 3 pelvis markers
    angles = pd.read_csv(walking5 / fill(PATHS.ik.angles, subject="W05", trial="walk-nodevice"), sep="\t")
    assert np.isnan(angles["hip_left_rad"].to_numpy()[:135]).all()
    assert angles["time_s"].iloc[0] == 0.0 and len(angles) == 1103


def test_walking5_is_turned_to_walk_forward_and_its_angles_are_a_walkers(walking5):
    markers = pd.read_csv(walking5 / fill(PATHS.markers.summary, subject="W05", trial="walk-nodevice"), sep="\t")
    markers = markers.iloc[0]
    assert markers.turn_deg == 180.0 and markers.heading_deg == pytest.approx(182.37, abs=0.01)
    angles = pd.read_csv(walking5 / fill(PATHS.ik.angles, subject="W05", trial="walk-nodevice"), sep="\t")
    hip, knee = np.degrees(angles["hip_left_rad"]), np.degrees(angles["knee_left_rad"])
    assert 30.0 < np.nanmax(hip) - np.nanmin(hip) < 60.0  # hip flexion range (measured 56.6 deg)
    assert 50.0 < np.nanmax(knee) < 75.0  # knee flexion peak in swing (measured 68.7 deg)
    x = angles["pelvis_x_m"].to_numpy()
    assert np.nanmax(x) - np.nanmin(x) > 3.0 and x[np.isfinite(x)][-1] > x[np.isfinite(x)][0]  # forward


def test_walking5_summary_flags_too_few_strides(walking5):
    summary = pd.read_csv(walking5 / PATHS.strides.summary, sep="\t").iloc[0]
    assert (summary.subject, summary.n_strides, summary.status) == ("W05", 0, "too_few_strides")
    assert summary.n_contacts_flagged == 1  # plate 1: the left heel lands behind it (off_plate)
    assert summary.turn_deg == 180.0 and summary.n_frames_left_out > 150


def test_walking5_and_the_same_walk_the_other_way_give_the_same_angles(tmp_path):
    """walking5 walks -X; the same recording turned half a turn about the lab's vertical walks +X: each trial is
    turned to walk along the model's +X, with no per-trial setting, and the joint angles agree."""
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.c3d_writer import write_c3d
    from loper_analysis.motion.ik_settings import IKSettings
    from loper_analysis.stages.ik.step import ik_trial
    from loper_analysis.stages.markers.step import markers

    rec = read_c3d(WALKING5)
    write_c3d(
        tmp_path / "plus_x.c3d", rec.marker_labels, rec.markers_m * np.array([-1.0, -1.0, 1.0]), rec.point_rate_hz
    )
    model = ROOT / "examples" / "rajagopal2016" / "Rajagopal2016.osim"
    tasks = ROOT / "examples" / "rajagopal2016" / "lower_body_ik_tasks.tsv"
    coordinate_map = yaml.safe_load((ROOT / "examples/rajagopal2016/config.yaml").read_text())["ik"]["coordinate_map"]
    angles = {}
    for name, c3d in (("minus_x", WALKING5), ("plus_x", tmp_path / "plus_x.c3d")):
        markers(
            c3d,
            tmp_path / f"{name}.trc",
            settings=MarkerSettings(walking_direction="auto", span_s=(2.0, 2.6)),
            summary_out=tmp_path / f"{name}.markers.tsv",
        )
        angles[name] = ik_trial(
            model,
            tmp_path / f"{name}.trc",
            tmp_path / f"{name}.mot",
            tmp_path / f"{name}.angles.tsv",
            # Rajagopal2016 as distributed, not scaled to this subject: the workflow's settings for a model_osim
            IKSettings(tasks_file=tasks, coordinate_map=coordinate_map, subjects_model=False),
        )
    turns = [pd.read_csv(tmp_path / f"{n}.markers.tsv", sep="\t")["turn_deg"].iloc[0] for n in ("minus_x", "plus_x")]
    assert turns == [180.0, 0.0]
    difference = np.degrees(
        angles["plus_x"].drop(columns=["time_s", "pelvis_x_m"]).to_numpy()
        - angles["minus_x"].drop(columns=["time_s", "pelvis_x_m"]).to_numpy()
    )
    # the markers agree to 1e-12 m; the solver, stopping at accuracy 1e-6 on this unscaled model, to 0.17 deg
    assert np.isfinite(difference).sum() > 900 and np.nanmax(np.abs(difference)) < 0.5
