"""The file steps of the processing chain on a synthetic trial with known kinematics, events and clocks.

Raw files are written from the synthetic lab (C3D with noisy markers and gaps in
the lab frame, GRF and sync analogs; robot log on a drifting clock); every
step (loper_analysis.stages.markers.step, model.step, ik.step) reads them back from disk.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.device.controller import DeviceParameters
from loper_analysis.device.loadcell import LoadcellSettings
from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.opensim_tables import read_markers, write_trc
from loper_analysis.io.robot_log import write_robot_log
from loper_analysis.motion.ik import joint_angle_table
from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
from loper_analysis.stages.events import step as event_steps
from loper_analysis.stages.ik import step as ik
from loper_analysis.stages.markers import step as marker_steps
from loper_analysis.stages.markers.step import MarkerSettings
from loper_analysis.stages.model import step as model
from loper_analysis.stages.strides import step as stride_steps
from loper_analysis.stages.transparency import step as transparency
from loper_analysis.synthetic.trials import (
    LabSettings,
    simulate_walking_trial,
    subject_static_recording,
    walking_recording,
)
from tests.stages.events.loadcell_step import loadcell

HEIGHT, MASS = 1.75, 70.0
LAB = LabSettings()


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    d = tmp_path_factory.mktemp("lab")
    write_recording(d / "static.c3d", subject_static_recording("S99", HEIGHT, MASS, 2.0, LAB, 7))
    osim_model = build_lower_body_model(HEIGHT, MASS)
    walk = simulate_walking_trial(
        20.0,
        LAB,
        3,
        HEIGHT,
        segment_parameters_from_model(osim_model),
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=DeviceParameters(),
    )
    write_recording(d / "walk.c3d", walking_recording(osim_model, walk, MASS, LAB, 11))
    write_robot_log(d / "walk.loper.tsv", walk.robot, LAB.robot_rate_hz, {"clock": "robot"})
    coords, events = walk.mocap_coordinates(LAB.marker_rate_hz), walk.mocap_events()
    # the chain
    marker_steps.markers(d / "static.c3d", d / "static.trc", settings=MarkerSettings(duration_s=1.0))
    gaps = marker_steps.markers(d / "walk.c3d", d / "walk.trc", d / "walk.gaps.tsv")
    model.generic_model(d / "generic.osim", HEIGHT, MASS)
    model.scale(model.ScaleFiles(d / "generic.osim", d / "static.trc", d / "scaled.osim"), MASS)
    for c in range(2):
        ik.ik_chunk(d / "scaled.osim", d / "walk.trc", d / f"walk.{c}.mot", c, 2)
    angles = ik.ik_join([d / "walk.0.mot", d / "walk.1.mot"], d / "walk.mot", d / "walk.angles.tsv")
    found = event_steps.events(
        d / "walk.c3d", d / "walk.events.tsv", EventSettings(grf_channels={"left": "Fz_left", "right": "Fz_right"})
    )
    force = loadcell(d / "walk.c3d", d / "walk.loper.tsv", d / "walk.force.tsv")
    strides = stride_steps.strides(
        d / "walk.angles.tsv",
        d / "walk.events.tsv",
        d / "walk.strides.tsv",
        d / "walk.cycles.tsv",
        d / "walk.force.tsv",
    )
    return {
        "dir": d,
        "coords": coords,
        "events": events,
        "gaps": gaps,
        "angles": angles,
        "found": found,
        "force": force,
        "strides": strides,
    }


def test_gaps_written_by_the_lab_are_filled(lab):
    assert len(lab["gaps"]) == LAB.n_gaps
    assert (lab["gaps"]["n_frames"] <= LAB.max_gap_frames).all()
    assert len(pd.read_csv(lab["dir"] / "walk.gaps.tsv", sep="\t")) == LAB.n_gaps


def test_ik_recovers_the_simulated_angles(lab):
    truth = joint_angle_table(lab["coords"])
    angles = lab["angles"]
    np.testing.assert_allclose(angles["time_s"], truth["time_s"], atol=1e-9)
    for col in ("hip_left_rad", "knee_left_rad", "ankle_left_rad", "hip_right_rad", "knee_right_rad"):
        err = np.abs(angles[col] - truth[col])[64:-64]  # half a second off the filter's ends
        # 0.5 mm marker noise, 40 Hz low-pass, scaled model: well under a degree
        assert err.max() < np.deg2rad(1.0), (col, np.rad2deg(err.max()))


def test_one_job_ik_equals_two_joined_chunks(lab):
    """ik_trial (the default single job) against ik_chunk x 2 + ik_join. The first chunk is the same
    computation (measured 2e-16 rad: the .mot round trip keeps every digit); the second starts its IK afresh,
    2.7e-5 rad off at its first frame, 4.7e-6 at its second, then within the solver's accuracy (1e-7)."""
    d = lab["dir"]
    whole = ik.ik_trial(d / "scaled.osim", d / "walk.trc", d / "whole.mot", d / "whole.angles.tsv")
    assert list(whole.columns) == list(lab["angles"].columns)
    np.testing.assert_allclose(whole["time_s"], lab["angles"]["time_s"], atol=1e-9)
    diff = np.abs(whole.drop(columns="time_s").to_numpy() - lab["angles"].drop(columns="time_s").to_numpy())
    seam = len(whole) // 2  # chunk_frames splits 2560 frames at 1280
    assert diff[:seam].max() < 1e-12
    assert diff[seam : seam + 2].max() < 5e-5
    assert diff[seam + 2 :].max() < 1e-6
    assert (d / "whole.mot").stat().st_size > 0


def test_events_within_one_analog_sample(lab):
    true, found = lab["events"], lab["found"]
    for (side, event), group in true.groupby(["side", "event"]):
        f = found[(found.side == side) & (found.event == event)]["time_s"].to_numpy()
        t = group["time_s"].to_numpy()
        t = t[(t > f.min() - 0.1) & (t < f.max() + 0.1)]
        assert len(f) == len(t), (side, event, len(f), len(t))
        assert np.abs(f - t).max() <= 1.0 / LAB.analog_rate_hz, (side, event, np.abs(f - t).max())


def test_loadcell_force_on_the_mocap_clock(lab):
    force = lab["force"]
    cm = force.attrs["clock_map"]
    # the mapped time is right within half a robot sample over the whole trial
    t = np.array([0.0, 20.0])
    true = -LAB.clock_offset_s + (1 + 1e-6 * LAB.clock_drift_ppm) * (t + LAB.clock_offset_s)
    assert np.abs(cm.to_mocap(t + LAB.clock_offset_s) - true).max() < 0.5e-3
    assert force["force_measured_n"].notna().all()
    rms = float(np.sqrt(np.mean(force["force_measured_n"] ** 2)))
    assert 1.5 < rms < 3.0, rms  # minimal-impedance walking: about 2 N in the study
    assert force["force_measured_n"].abs().max() < 10.0  # no start transient, no safety stop


def test_strides_and_outliers(lab):
    strides = lab["strides"].strides
    hs = lab["events"].query("side == 'left' and event == 'heel_strike'")["time_s"].to_numpy()
    assert len(strides) >= len(hs) - 3
    np.testing.assert_allclose(strides["duration_s"].mean(), 60 / 36, rtol=0.05)
    assert strides["removed"].sum() <= 0.2 * len(strides)
    assert {"rms_force_stance_n", "max_abs_force_swing_n"} <= set(strides.columns)
    cycles = pd.read_csv(lab["dir"] / "walk.cycles.tsv", sep="\t")
    assert len(cycles) == 3 * 101 * len(strides)


def test_model_marker_missing_from_the_trial_is_named(lab, tmp_path):
    t, X, labels = read_markers(lab["dir"] / "walk.trc")
    i = labels.index("LKNE")
    write_trc(tmp_path / "cut.trc", t, np.delete(X, i, axis=1), labels[:i] + labels[i + 1 :])
    with pytest.raises(
        LoperInputError,
        match=r"cut\.trc with .*scaled\.osim: marker\(s\) \['LKNE'\] of the model's "
        r"marker set are missing",
    ):
        ik.ik_chunk(lab["dir"] / "scaled.osim", tmp_path / "cut.trc", tmp_path / "x.mot", 0, 1)
    assert not (tmp_path / "x.mot").exists()


def test_missing_belt_channel_is_named(lab, tmp_path):
    with pytest.raises(LoperInputError, match="Fz_belt3"):
        event_steps.events(
            lab["dir"] / "walk.c3d",
            tmp_path / "e.tsv",
            EventSettings(grf_channels={"left": "Fz_belt3", "right": "Fz_right"}),
        )
    assert not (tmp_path / "e.tsv").exists()


def test_stride_summary_flags_too_few_strides(lab, tmp_path):
    walk = lab["dir"] / "walk.strides.tsv"
    table = pd.read_csv(walk, sep="\t")
    few = table.copy()
    few.loc[3:, "removed"] = True
    few.loc[3:, "reason"] = "knee: 30.0 % of samples outside 1.5·IQR"
    few.to_csv(tmp_path / "few.strides.tsv", sep="\t", index=False)
    out = stride_steps.strides_summary(
        [("S99", "walk"), ("S99", "few")], [walk, tmp_path / "few.strides.tsv"], tmp_path / "summary.tsv", min_valid=5
    )
    ok, flagged = out.iloc[0], out.iloc[1]
    assert ok.status == "ok" and ok.n_strides == len(table) and ok.n_kept == (~table.removed).sum()
    assert ok.n_perturbed == 0
    assert flagged.status == "too_few_strides" and flagged.n_kept == 3
    assert flagged.n_removed == flagged.n_removed_knee == len(table) - 3 and flagged.n_removed_hip == 0
    assert pd.read_csv(tmp_path / "summary.tsv", sep="\t").status.tolist() == ["ok", "too_few_strides"]


def test_fewer_than_five_valid_strides_warn(lab, tmp_path):
    d = lab["dir"]
    events = pd.read_csv(d / "walk.events.tsv", sep="\t")
    # keep 5 left heel strikes: 4 strides, each kept (too few for the analysis, enough for the outlier rule)
    hs = events[(events.side == "left") & (events.event == "heel_strike")].time_s.to_numpy()
    short = events[events.time_s <= hs[4] + 1e-9]
    short.to_csv(tmp_path / "short.events.tsv", sep="\t", index=False)
    with pytest.warns(TooFewStridesWarning, match="4"):
        tables = stride_steps.strides(
            d / "walk.angles.tsv", tmp_path / "short.events.tsv", tmp_path / "s.strides.tsv", tmp_path / "s.cycles.tsv"
        )
    assert len(tables.strides) == 4 and tables.too_few_strides


def test_transparency_of_a_trial_against_itself(lab, tmp_path):
    """The same trial as both conditions: RMSD 0 everywhere, so transparent; tables and figure written."""
    d = lab["dir"]
    strides, cycles = d / "walk.strides.tsv", d / "walk.cycles.tsv"
    files = {s: transparency.TransparencyFiles(strides, cycles, strides, cycles) for s in ("S98", "S99")}
    out = transparency.transparency(files, tmp_path / "rmsd.tsv", tmp_path / "force.tsv", tmp_path / "t.png")
    rmsd = pd.read_csv(tmp_path / "rmsd.tsv", sep="\t")
    assert len(rmsd) == 3 * 2 * 3  # (2 subjects + all) x 2 phases x 3 joints
    np.testing.assert_allclose(rmsd["rmsd_rad"], 0.0, atol=1e-12)
    assert rmsd["transparent"].all()
    force = pd.read_csv(tmp_path / "force.tsv", sep="\t")
    assert force["subject"].tolist() == ["S98", "S98", "S99", "S99", "all", "all"]
    np.testing.assert_allclose(force["rms_force_sd_n"].iloc[-2:], 0.0, atol=1e-12)  # identical subjects
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert out.angles_rad["device"].shape == (2 * int((~lab["strides"].strides["removed"]).sum()), 101, 3)


@pytest.mark.parametrize("n_strides", [0, 3])
def test_fewer_strides_than_the_outlier_rule_needs_are_kept_unjudged_and_flagged(lab, tmp_path, n_strides):
    """0 or 3 complete strides: no stop; none removed, fractions empty, two warnings, too_few_strides."""
    d = lab["dir"]
    events = pd.read_csv(d / "walk.events.tsv", sep="\t")
    hs = events[(events.side == "left") & (events.event == "heel_strike")].time_s.to_numpy()
    events[events.time_s <= hs[n_strides] + 1e-9].to_csv(tmp_path / "short.events.tsv", sep="\t", index=False)
    with pytest.warns(TooFewStridesWarning) as caught:
        tables = stride_steps.strides(
            d / "walk.angles.tsv",
            tmp_path / "short.events.tsv",
            tmp_path / "s.strides.tsv",
            tmp_path / "s.cycles.tsv",
            d / "walk.force.tsv",
        )
    messages = [str(w.message) for w in caught]
    assert f"{n_strides} complete unperturbed left stride(s)" in messages[0] and "needs at least 4" in messages[0]
    assert f"only {n_strides} valid stride(s), fewer than the 5 required" in messages[1]
    assert tables.too_few_strides
    written = pd.read_csv(tmp_path / "s.strides.tsv", sep="\t")
    assert list(written.columns) == list(lab["strides"].strides.columns)  # the same columns, also without strides
    assert len(written) == n_strides and not written.removed.any()
    assert written.filter(like="fraction_outlying_").isna().all().all()
    # the first strides are the trial's own: same times and force as in the whole trial
    whole = lab["strides"].strides.iloc[:n_strides]
    cols = ["heel_strike_s", "rms_force_swing_n"]
    np.testing.assert_allclose(written[cols].to_numpy(float), whole[cols].to_numpy(float), rtol=1e-8)
    assert len(pd.read_csv(tmp_path / "s.cycles.tsv", sep="\t")) == 3 * 101 * n_strides


def test_transparency_leaves_out_a_subject_with_too_few_strides(lab, tmp_path):
    """S98 with 3 kept strides with the device: its rows keep the counts with empty metrics; the group is S99."""
    d = lab["dir"]
    strides = pd.read_csv(d / "walk.strides.tsv", sep="\t")
    few = strides.copy()
    few["removed"] = few.index >= 3
    few.to_csv(tmp_path / "few.strides.tsv", sep="\t", index=False)
    walk, cycles = d / "walk.strides.tsv", d / "walk.cycles.tsv"
    with pytest.warns(TooFewStridesWarning, match="subject S98: .* and 3 with the device, fewer than 5"):
        transparency.transparency(
            {
                "S98": transparency.TransparencyFiles(walk, cycles, tmp_path / "few.strides.tsv", cycles),
                "S99": transparency.TransparencyFiles(walk, cycles, walk, cycles),
            },
            tmp_path / "rmsd.tsv",
            tmp_path / "force.tsv",
            tmp_path / "t.png",
        )
    rmsd = pd.read_csv(tmp_path / "rmsd.tsv", sep="\t")
    n = int((~strides.removed).sum())
    assert rmsd.subject.tolist() == ["S98"] * 6 + ["S99"] * 6 + ["all"] * 6
    s98, s99, group = rmsd[rmsd.subject == "S98"], rmsd[rmsd.subject == "S99"], rmsd[rmsd.subject == "all"]
    assert (s98.n_strides_device == 3).all() and (s98.n_strides_no_device == n).all()
    assert s98[["rmsd_rad", "sd_rad", "isv_ave_rad", "transparent"]].isna().all().all()
    np.testing.assert_allclose(s99.rmsd_rad, 0.0, atol=1e-12)
    assert s99.transparent.all() and (group.n_strides_device == n).all()
    np.testing.assert_allclose(group.isv_ave_rad, 2 * s99.sd_rad)  # ISV_ave of one subject: 2 sigma
    force = pd.read_csv(tmp_path / "force.tsv", sep="\t")
    assert force.subject.tolist() == ["S98", "S98", "S99", "S99", "all", "all"]
    assert force.loc[force.subject == "S98", "rms_force_mean_n"].isna().all()
    np.testing.assert_allclose(
        force.loc[force.subject == "all", "rms_force_mean_n"], force.loc[force.subject == "S99", "rms_force_mean_n"]
    )


def test_transparency_without_any_subject_left_writes_empty_group_rows(lab, tmp_path):
    d = lab["dir"]
    strides = pd.read_csv(d / "walk.strides.tsv", sep="\t")
    strides.iloc[:1].to_csv(tmp_path / "one.strides.tsv", sep="\t", index=False)
    with pytest.warns(TooFewStridesWarning, match="and 1 with the device, fewer than 5"):
        transparency.transparency(
            {
                "S98": transparency.TransparencyFiles(
                    d / "walk.strides.tsv", d / "walk.cycles.tsv", tmp_path / "one.strides.tsv", d / "walk.cycles.tsv"
                )
            },
            tmp_path / "rmsd.tsv",
            tmp_path / "force.tsv",
            tmp_path / "t.png",
        )
    rmsd = pd.read_csv(tmp_path / "rmsd.tsv", sep="\t")
    assert rmsd.subject.tolist() == ["S98"] * 6 + ["all"] * 6
    assert (rmsd.loc[rmsd.subject == "all", ["n_strides_no_device", "n_strides_device"]] == 0).all().all()
    assert rmsd.rmsd_rad.isna().all() and rmsd.transparent.isna().all() and rmsd.study_rmsd_rad.notna().all()
    force = pd.read_csv(tmp_path / "force.tsv", sep="\t")
    assert force.subject.tolist() == ["S98", "S98", "all", "all"] and force.n_strides.tolist() == [1, 1, 0, 0]
    assert (tmp_path / "t.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_events_and_loadcell_from_one_reading_write_the_bytes_of_the_two_steps(lab, tmp_path):
    """The workflow's one-process step for trials with the device against the two steps run on their own."""
    d = lab["dir"]
    grf = {"left": "Fz_left", "right": "Fz_right"}
    event_steps.events(
        d / "walk.c3d",
        tmp_path / "alone.events.tsv",
        EventSettings(grf_channels=grf),
        contacts_out=tmp_path / "alone.contacts.tsv",
    )
    loadcell(
        d / "walk.c3d", d / "walk.loper.tsv", tmp_path / "alone.force.tsv", native_out=tmp_path / "alone.native.tsv"
    )
    table, force = event_steps.events_loadcell(
        d / "walk.c3d",
        d / "walk.loper.tsv",
        tmp_path / "one.events.tsv",
        tmp_path / "one.contacts.tsv",
        tmp_path / "one.force.tsv",
        tmp_path / "one.native.tsv",
        EventSettings(grf_channels=grf),
        LoadcellSettings(cutoff_hz=40.0),
    )
    for kind in ("events", "contacts", "force", "native"):
        assert (tmp_path / f"one.{kind}.tsv").read_bytes() == (tmp_path / f"alone.{kind}.tsv").read_bytes(), kind
    assert len(table) == len(lab["found"]) and len(force) == len(lab["force"])


def test_events_and_loadcell_write_nothing_when_the_robot_log_is_bad(lab, tmp_path):
    d = lab["dir"]
    lines = (d / "walk.loper.tsv").read_text().splitlines(keepends=True)
    header = sum(line.startswith("#") for line in lines) + 1
    cells = lines[header + 20].split("\t")
    cells[2] = "nan"  # force_measured_n of one sample
    lines[header + 20] = "\t".join(cells)
    bad = tmp_path / "bad.loper.tsv"
    bad.write_text("".join(lines))
    out = tmp_path / "out"
    with pytest.raises(LoperInputError, match=r"bad\.loper\.tsv: column 'force_measured_n', sample 20 .*non-finite"):
        event_steps.events_loadcell(
            d / "walk.c3d",
            bad,
            out / "e.tsv",
            out / "c.tsv",
            out / "f.tsv",
            out / "n.tsv",
            EventSettings(grf_channels={"left": "Fz_left", "right": "Fz_right"}),
        )
    assert not out.exists()  # the events were found, but nothing is written unless both steps succeed
