"""End to end on a recorded subject in the style of a real lab: QTM-like C3D files with treadmill force
platforms, the lab's own marker names, gaps, a late first frame, MATLAB robot logs, and the study's gait2392
scaled with a lab's ScaleTool setup (the settings of ``examples/gait2392/config.yaml``), through the
workflow to the impedance table.

The raw files come from ``tests/lab_export_session.lab_export_session`` (a simulated subject
whose markers are gait2392's, whose perturbation responses follow a known impedance with gait2392's
own segment table); the pipeline meets them as a lab's export: labels ``Subject:L_FCC``, plates not
zeroed with decoy voltage channels named like force channels, 40-frame gaps, first frame 1000 (the file
starts at 7.8125 s), robot logs as ``.mat``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.io.opensim_tables import read_mot
from loper_analysis.io.osim import read_model
from loper_analysis.io.segment_table import read_segments
from loper_analysis.layout import fill
from loper_analysis.motion.segments import segments_from_model
from loper_analysis.stages import study_paths
from tests.lab_export_session import LabExportFiles, LabExportSettings, lab_export_session
from tests.workflow_copy import copy_workflow, snakemake

PATHS = study_paths()

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials (pytest -m "not slow" leaves them out)
ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "gait2392"
GENERIC = EXAMPLE / "gait2392_simbody.osim"
MASS_KG = 75.1646  # gait2392's own mass: the scaled model keeps its masses
FIRST_TIME_S = 1000 / 128.0
TRUE_IMPEDANCE = {"hip": (55.0, 3.5), "knee": (3.0, 0.1), "ankle": (8.0, 0.3)}  # K (N·m/rad), D (N·m·s/rad)
TARGETS = (PATHS.impedance.table, PATHS.strides.summary, fill(PATHS.grf.mot, subject="R01", trial="pert050-1"))


def _test_config() -> dict:
    """What this test sets on top of the default config and the gait2392 example: one subject, one onset."""
    return {
        "subjects": "config/subjects.tsv",
        "device": {"subject": "R01"},
        "trials": {"perturbation_onsets_ms": [50], "perturbation_repeats": 1},
    }


@pytest.fixture(scope="module")
def lab_run(tmp_path_factory):
    """The workflow on one recorded subject: its session (walking with the device, one perturbation trial)."""
    work = tmp_path_factory.mktemp("lab")
    copy_workflow(work)
    files = LabExportFiles(
        work / "data/raw/R01", GENERIC, EXAMPLE / "gait2392_Scale_MarkerSet.xml", EXAMPLE / "qtm_label_map.tsv"
    )
    truth = lab_export_session(
        files,
        "R01",
        ["walk-device", "pert050-1"],  # the default design: pulses 50 ms after toe-off in pert050-1
        1.80,
        MASS_KG,
        LabExportSettings(seed=7, walking_duration_s=40.0, perturb_every_strides=(2, 3)),
        impedance=[v for j in ("hip", "knee", "ankle") for v in TRUE_IMPEDANCE[j]],
    )
    (work / "config/subjects.tsv").write_text(f"subject\tsource\theight_m\tmass_kg\nR01\trecorded\t1.80\t{MASS_KG}\n")
    (work / "config/test.yaml").write_text(yaml.safe_dump(_test_config(), sort_keys=False))
    res = snakemake(work, *TARGETS, "--configfile", "examples/gait2392/config.yaml", "config/test.yaml")
    assert res.returncode == 0, res.stderr[-3000:]
    return work, truth


def test_the_raw_files_are_a_labs(lab_run):
    work, _ = lab_run
    rec = read_c3d(work / "data/raw/R01/pert050-1.c3d")
    assert rec.marker_labels[0].startswith("Subject:") and "Subject:L_FCC" in rec.marker_labels
    assert rec.first_frame == 1000 and rec.time_s[0] == FIRST_TIME_S
    assert "FP1_FZ" in rec.analog_labels and rec.analog_units[rec.analog_labels.index("FP1_FZ")] == "V"
    assert np.isnan(rec.markers_m).any(axis=2).sum(axis=0).max() >= 40  # long gaps
    plates = read_force_platforms(work / "data/raw/R01/pert050-1.c3d")
    assert [p.number for p in plates] == [1, 2]
    assert np.percentile(plates[0].force_n[:, 2], 1) < -30.0  # not zeroed: the unloaded left belt reads about -40 N


def test_segment_table_comes_from_the_scaled_gait2392(lab_run):
    work, _ = lab_run
    table = read_segments(work / fill(PATHS.model.segments, subject="R01"))
    generic = segments_from_model(read_model(GENERIC), "l", attachment_fraction=0.8)
    np.testing.assert_allclose(table.mass_kg, generic.mass_kg, rtol=1e-9)  # the subject's mass is gait2392's
    np.testing.assert_allclose(table.cart_mass_kg, generic.cart_mass_kg, rtol=1e-9)
    # the static trial holds gait2392's own markers with 0.5 mm noise: scale factors of 1 within 0.5 %
    np.testing.assert_allclose(table.length_m, generic.length_m, rtol=5e-3)
    np.testing.assert_allclose(table.inertia_kg_m2, generic.inertia_kg_m2, rtol=2e-2)


def test_angles_keep_the_files_clock_and_match_the_simulation(lab_run):
    work, truth = lab_run
    angles = pd.read_csv(work / fill(PATHS.ik.angles, subject="R01", trial="pert050-1"), sep="\t")
    assert angles["time_s"].iloc[0] == FIRST_TIME_S
    coordinates = truth["pert050-1"][1].coordinates
    for ours, theirs, sign in (
        ("hip_left_rad", "hip_flexion_l", 1),
        ("knee_left_rad", "knee_angle_l", -1),
        ("ankle_left_rad", "ankle_angle_l", 1),
    ):
        error_deg = np.degrees(angles[ours].to_numpy() - sign * coordinates[theirs].to_numpy())
        assert np.sqrt(np.mean(error_deg**2)) < 0.3, ours  # measured 0.07-0.14 deg
        assert np.abs(error_deg).max() < 1.0, ours  # measured 0.26-0.60 deg


def test_events_from_the_plates_match_the_true_gait_events(lab_run):
    work, truth = lab_run
    for trial in ("walk-device", "pert050-1"):
        true = truth[trial][0].mocap_events()
        events = pd.read_csv(work / fill(PATHS.events.events, subject="R01", trial=trial), sep="\t")
        plain = events[events.event.isin(["heel_strike", "toe_off"])]
        for (side, kind), ours in plain.groupby(["side", "event"]):
            expected = true[(true.side == side) & (true.event == kind)]["time_s"].to_numpy() + FIRST_TIME_S
            gaps_ms = [1e3 * np.min(np.abs(expected - t)) for t in ours["time_s"]]
            assert max(gaps_ms) < 5.0, (trial, side, kind)  # measured at most 0.97 ms (1 sample at 1024 Hz)
            assert len(ours) >= len(expected) - 1, (trial, side, kind)  # the first contact is cut by the start
        contacts = pd.read_csv(work / fill(PATHS.events.contacts, subject="R01", trial=trial), sep="\t")
        clean = contacts[contacts.flag == "ok"]
        assert (clean["side"] == clean["plate"].map({1: "left", 2: "right"})).all()
    summary = pd.read_csv(work / PATHS.strides.summary, sep="\t")
    assert summary["n_contacts_flagged"].tolist() == [0, 0] and (summary["status"] == "ok").all()


def test_ground_reaction_mot_holds_the_belt_force_in_the_model_frame(lab_run):
    work, truth = lab_run
    mot = read_mot(work / fill(PATHS.grf.mot, subject="R01", trial="pert050-1"))
    force = truth["pert050-1"][1].force_n["left"]  # on the body, lab frame (Z up), N
    loaded = mot["1_ground_force_vy"].to_numpy() != 0.0
    assert loaded.mean() > 0.3
    assert mot["time_s"].iloc[0] == pytest.approx(FIRST_TIME_S, abs=1e-9)
    np.testing.assert_allclose(mot["1_ground_force_vy"].to_numpy()[loaded], force[loaded, 2], atol=0.05)
    np.testing.assert_allclose(mot["1_ground_force_vx"].to_numpy()[loaded], force[loaded, 0], atol=0.05)


def test_impedance_table_recovers_the_true_impedance(lab_run):
    work, _ = lab_run
    table = pd.read_csv(work / PATHS.impedance.table, sep="\t").set_index("joint")
    assert table.loc["ankle", "status"] == "ok", table["reason"]
    # six strides: the hip's K interval is informative, its D interval (1.83 ... 4.84) wider than the study's
    # whole hip D range (1.9-4.6): the data cannot place the hip's damping within it
    hip = table.loc["hip"]
    assert hip.status == "not_identifiable" and "D_hip" in hip.reason and "K_hip" not in hip.reason
    assert "wider than the plausible range 1.9–4.6 N·m·s/rad" in hip.reason
    assert hip.D_ci95_high_nms_per_rad - hip.D_ci95_low_nms_per_rad >= 4.6 - 1.9
    # one 40 s trial, 12 unperturbed strides: too few for the conditional counterfactual, the fit says it took the
    # matched stride; 6 strides kept: the knee's K and D intervals (0 ... 5.4, 0 ... 0.65) hold both 0 and the
    # study's whole knee range (K up to 3.5, D up to 0.14): the data cannot tell their size
    knee = table.loc["knee"]
    assert table["reason"].str.contains("matched stride instead of the conditional counterfactual: 12 unpert").all()
    assert knee.status == "not_identifiable" and knee.K_ci95_low_nm_per_rad == 0 and knee.D_ci95_low_nms_per_rad == 0
    assert knee.D_ci95_high_nms_per_rad >= 0.14 and "D_knee" in knee.reason and "plausible range" in knee.reason
    assert knee.K_ci95_high_nm_per_rad >= 3.5 and "K_knee" in knee.reason
    for joint, (k, d) in TRUE_IMPEDANCE.items():
        row = table.loc[joint]
        if joint != "ankle":  # the ankle's CI is narrow and its D meets the truth only to 0.001 N·m·s/rad
            assert row.K_ci95_low_nm_per_rad <= k <= row.K_ci95_high_nm_per_rad, joint
            assert row.D_ci95_low_nms_per_rad <= d <= row.D_ci95_high_nms_per_rad, joint
    assert table.loc["hip", "K_nm_per_rad"] == pytest.approx(55.0, rel=0.10)  # measured 59.0
    assert table.loc["hip", "D_nms_per_rad"] == pytest.approx(3.5, rel=0.10)  # measured 3.33
    assert table.loc["ankle", "K_nm_per_rad"] == pytest.approx(8.0, rel=0.05)  # measured 7.95
    assert (table["vaf_pct"] > 99.0).all()
