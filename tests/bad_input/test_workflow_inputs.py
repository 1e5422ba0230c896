"""Bad input at the workflow level: every refusal names the file, the field and the value, writes nothing
under results/ or data/ (but the failed job's log) and leaves the results of earlier runs as they were.

One module-wide project holds a recorded subject R01 (a static trial and a walking trial with the device,
written by the simulated lab) whose markers, events and forces were already processed. Each test breaks
one input in a copy of it. Where the readers' refusals are tested in detail elsewhere (tests/io,
tests/stages), this suite runs the rule's file step on the project's paths, with the rule's settings
from the config; a few cases go through Snakemake itself (real jobs, or dry runs for the checks made
before any work starts).
"""

from __future__ import annotations

import dataclasses
import hashlib
import re
import shutil
import subprocess
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.trial_events import EventSettings
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import write_recording
from loper_analysis.io.opensim_tables import read_markers, write_trc
from loper_analysis.layout import fill
from loper_analysis.motion.ik_settings import IKSettings
from loper_analysis.stages import study_paths
from loper_analysis.stages.events import step as event_steps
from loper_analysis.stages.ik import step as ik
from loper_analysis.stages.markers import step as marker_steps
from loper_analysis.stages.markers.step import MarkerSettings
from loper_analysis.stages.settings import stage_settings
from tests.stages.events.loadcell_step import loadcell
from tests.workflow_copy import snakemake

PATHS = study_paths()

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials (pytest -m "not slow" leaves them out)
ROOT = Path(__file__).resolve().parents[2]
SUBJECT, HEIGHT_M, MASS_KG = "R01", 1.75, 70.0
RAW = f"data/raw/{SUBJECT}"
WALK = "walk-device"
#: What the project's earlier run made (besides logs and benchmarks).
GOOD_TARGETS = (
    fill(PATHS.markers.trc, subject=SUBJECT, trial="static"),
    fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK),
    fill(PATHS.events.events, subject=SUBJECT, trial=WALK),
    fill(PATHS.events.force, subject=SUBJECT, trial=WALK),
    fill(PATHS.model.generic, subject=SUBJECT),
)


def _snakemake(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return snakemake(cwd, *args, timeout=300)


@pytest.fixture(scope="module")
def project(tmp_path_factory) -> Path:
    """The workflow with one recorded subject (8 s of walking) and the results of its first stages."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.io.robot_log import write_robot_log
    from loper_analysis.motion.model import (
        build_lower_body_model,
        segment_parameters_from_model,
    )
    from loper_analysis.synthetic.trials import (
        LabSettings,
        simulate_walking_trial,
        subject_static_recording,
        walking_recording,
    )

    work = tmp_path_factory.mktemp("lab")
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, work / item)
    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    cfg["device"]["subject"] = SUBJECT
    cfg["study"].update(perturbation_onsets_ms=[50], perturbation_repeats=1)
    (work / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    (work / "config/subjects.tsv").write_text(
        f"subject\tsource\theight_m\tmass_kg\n{SUBJECT}\trecorded\t{HEIGHT_M}\t{MASS_KG}\n"
    )
    lab, raw = LabSettings(), work / RAW
    raw.mkdir(parents=True)
    write_recording(raw / "static.c3d", subject_static_recording(SUBJECT, HEIGHT_M, MASS_KG, 2.0, lab, 7))
    model = build_lower_body_model(HEIGHT_M, MASS_KG)
    for folder, seed in ((raw, 3), (work / "elsewhere", 4)):  # the trial, and one recorded at another time
        walk = simulate_walking_trial(
            8.0,
            lab,
            seed,
            HEIGHT_M,
            segment_parameters_from_model(model),
            timing_cv=0.03,
            amplitude_cv=0.05,
            device=DeviceParameters(),
        )
        folder.mkdir(exist_ok=True)
        write_recording(folder / f"{WALK}.c3d", walking_recording(model, walk, MASS_KG, lab, seed + 10))
        write_robot_log(folder / f"{WALK}.loper.tsv", walk.robot, lab.robot_rate_hz, {"clock": "robot"})
    res = _snakemake(work, *GOOD_TARGETS)
    assert res.returncode == 0, res.stderr[-3000:]
    return work


@pytest.fixture
def lab(project, tmp_path, monkeypatch) -> Path:
    """A copy of the project (files' times kept) as the working directory."""
    work = tmp_path / "lab"
    shutil.copytree(project, work, symlinks=True)
    monkeypatch.chdir(work)
    return work


def _config(work: Path) -> dict:
    return yaml.safe_load((work / "config/config.yaml").read_text())


def _state(work: Path) -> dict[str, tuple[int, str]]:
    """Every file under results/ and data/ (hidden ones too): modification time and content hash."""
    return {
        str(p.relative_to(work)): (p.stat().st_mtime_ns, hashlib.sha256(p.read_bytes()).hexdigest())
        for top in ("results", "data")
        for p in sorted((work / top).rglob("*"))
        if p.is_file()
    }


def _refused(work: Path, run, words, log: str | None = None) -> str:
    """Run a refusal; check its message names every one of ``words`` and that the files are as they were.

    ``run`` raises LoperInputError (a file step) or returns Snakemake's finished process (then the
    console's output is the message). ``log``: the failed job's log, the only file allowed to appear.
    """
    before = _state(work)
    assert set(GOOD_TARGETS) <= set(before)
    try:
        res = run()
    except LoperInputError as exc:
        message = str(exc)
    else:
        assert res.returncode != 0
        message = res.stdout + res.stderr
    for word in words:
        assert word in message, (word, message[-2000:])
    after = _state(work)
    if log is not None:
        after.pop(log)
        text = (work / log).read_text()
        assert words[0] in text and "Traceback (most recent call last)" in text
    assert after == before  # nothing new, nothing rewritten, nothing removed
    return message


# --------------------------------------------------------------------------- the steps of the rules


def _markers(cfg: dict, c3d: str, label_map=None):
    """The markers rule's step for the walking trial, with its outputs and the config's settings."""
    m = cfg["markers"]
    return marker_steps.markers(
        c3d,
        fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK),
        fill(PATHS.markers.gaps, subject=SUBJECT, trial=WALK),
        dataclasses.replace(stage_settings(cfg, "markers"), label_map=label_map or m["label_map"] or None),
        summary_out=fill(PATHS.markers.summary, subject=SUBJECT, trial=WALK),
    )


def _loadcell(cfg: dict, log: str = f"{RAW}/{WALK}.loper.tsv", c3d: str = f"{RAW}/{WALK}.c3d"):
    return loadcell(
        c3d,
        log,
        fill(PATHS.events.force, subject=SUBJECT, trial=WALK),
        stage_settings(cfg, "events").loadcell,
    )


def _events(cfg: dict, grf_channels: dict):
    return event_steps.events(
        f"{RAW}/{WALK}.c3d",
        fill(PATHS.events.events, subject=SUBJECT, trial=WALK),
        dataclasses.replace(stage_settings(cfg, "events").events, grf_channels=grf_channels),
        contacts_out=fill(PATHS.events.contacts, subject=SUBJECT, trial=WALK),
    )


def _ik(cfg: dict, trc: Path, static_trc: str | None = None):
    return ik.ik_trial(
        fill(PATHS.model.generic, subject=SUBJECT),
        trc,
        fill(PATHS.ik.mot, subject=SUBJECT, trial=WALK),
        fill(PATHS.ik.angles, subject=SUBJECT, trial=WALK),
        stage_settings(cfg, "ik"),
        static_trc=static_trc,
    )


# --------------------------------------------------------------------------- C3D files


def _c3d_bytes(work: Path) -> bytes:
    return (work / RAW / f"{WALK}.c3d").read_bytes()


@pytest.mark.parametrize(
    ("name", "damage", "words"),
    [
        ("truncated", lambda b, w: b[: len(b) // 2], ["truncated file", "declares 1024 frames but only 511"]),
        (
            "foreign",
            lambda b, w: (w / RAW / f"{WALK}.loper.tsv").read_bytes(),
            ["not a readable C3D file", "must be a valid c3d file"],
        ),
        ("empty", lambda b, w: b"", ["not a readable C3D file", "File is empty"]),
        (
            "unknown unit",
            lambda b, w: b.replace(b"\x01\x02mm", b"\x01\x02yd", 1),
            ["unknown POINT:UNITS 'yd'", "expected one of mm, cm, m"],
        ),
    ],
    ids=["truncated", "foreign", "empty", "unknown-unit"],
)
def test_unreadable_c3d_is_refused_by_the_markers_step(lab, name, damage, words):
    c3d = lab / RAW / f"{WALK}.c3d"
    c3d.write_bytes(damage(c3d.read_bytes(), lab))
    _refused(lab, lambda: _markers(_config(lab), f"{RAW}/{WALK}.c3d"), [f"{RAW}/{WALK}.c3d: ", *words])


def test_truncated_c3d_of_a_new_trial_stops_its_job_with_one_line_and_a_log(lab):
    """Through Snakemake: the console names file and cause in one line; the job's log is the only new file."""
    (lab / RAW / "pert050-1.c3d").write_bytes(_c3d_bytes(lab)[:300_000])
    message = _refused(
        lab,
        lambda: _snakemake(lab, fill(PATHS.markers.trc, subject=SUBJECT, trial="pert050-1")),
        [f"{RAW}/pert050-1.c3d: truncated file: the header declares 1024 frames but only"],
        log=PATHS.log("markers", f"{SUBJECT}/pert050-1"),
    )
    assert "Traceback" not in message


def test_label_map_entry_the_file_lacks_is_refused(lab):
    _refused(
        lab,
        lambda: _markers(_config(lab), f"{RAW}/{WALK}.c3d", {"L_FCC": "LHEE"}),
        [f"{RAW}/{WALK}.c3d: markers.label_map: label(s) L_FCC not in the file", "RASI, LASI"],
    )


def test_a_rotation_that_hangs_the_subject_below_the_floor_is_refused(lab):
    """[90, 0, 0] for the Z-up lab: the pelvis lies along the model's -Y from the feet; the message offers the sign."""
    cfg = _config(lab)
    cfg["markers"]["lab_to_model_rotation_deg"] = [90, 0, 0]
    _refused(
        lab,
        lambda: _markers(cfg, f"{RAW}/{WALK}.c3d"),
        [
            f"{RAW}/{WALK}.c3d: markers.lab_to_model_rotation_deg (--rotate-deg) [90, 0, 0] does not stand the "
            "subject up: its pelvis lies along the model's -Y from its feet",
            "the markers' up is model -Y: try [-90, 0, 0]",
        ],
    )


def test_static_trial_in_which_the_subject_moves_is_refused(lab):
    """The subject walks off at 0.3 m/s: over any second every marker moves 87 mm RMS; the message names the
    stillest second (by the markers' noise), found here by brute force over every start frame."""
    from loper_analysis.stages.model import step as model

    t, X, labels = read_markers(fill(PATHS.markers.trc, subject=SUBJECT, trial="static"))
    X[:, :, 0] += 0.3 * (t - t[0])[:, None]
    write_trc(lab / "moving.trc", t, X, labels)
    m = _config(lab)["model"]
    n = int(np.sum(t < t[0] + m["static_duration_s"] - 1e-9))
    largest = [
        np.nanmax(np.sqrt(np.nanmean(np.sum((X[s : s + n] - np.nanmean(X[s : s + n], axis=0)) ** 2, axis=2), axis=0)))
        for s in range(t.size - n + 1)
    ]
    s = int(np.argmin(largest))
    _refused(
        lab,
        lambda: model.scale(
            model.ScaleFiles(
                fill(PATHS.model.generic, subject=SUBJECT),
                lab / "moving.trc",
                fill(PATHS.model.scaled, subject=SUBJECT),
            ),
            MASS_KG,
            model.ModelSettings(
                static_duration_s=m["static_duration_s"], max_motion_rms_m=m["static_max_motion_rms_m"]
            ),
            lab_labels=fill(PATHS.markers.summary, subject=SUBJECT, trial="static"),
        ),
        [
            f"moving.trc: the subject does not stand still in the scaling window {t[s]:.4f} .. {t[s + n - 1]:.4f} s "
            "of the static trial: marker(s) ",
            " 87 mm, ",
            f"and {len(labels) - 5} more move more than model.static_max_motion_rms_m 0.05 m RMS about their mean; "
            f"it is the stillest 1 s (model.static_duration_s) of the static trial ({t[0]:.4f} .. {t[-1]:.4f} s",
        ],
    )


def test_label_map_typo_in_a_model_name_is_named_as_such_by_scaling(lab):
    """A label mapped to 'LHEEL' (the model's marker is LHEE): not "the static trial lacks LHEE" alone."""
    from loper_analysis.stages.model import step as model

    t, X, labels = read_markers(fill(PATHS.markers.trc, subject=SUBJECT, trial="static"))
    labels[labels.index("LHEE")] = "LHEEL"
    write_trc(lab / "typo.trc", t, X, labels)
    _refused(
        lab,
        lambda: model.scale(
            model.ScaleFiles(
                fill(PATHS.model.generic, subject=SUBJECT), lab / "typo.trc", fill(PATHS.model.scaled, subject=SUBJECT)
            ),
            MASS_KG,
            lab_labels={"LHEEL": "L_FCC"},
        ),
        [
            "typo.trc: measurement marker(s) ['LHEE'] are not in the static trial",
            "the trial's marker(s) 'L_FCC' mapped to LHEEL (the model has LHEE) are not on the model: a typo in the "
            "label map (markers.label_map, markers.trial_label_maps)?",
        ],
    )


def test_model_marker_missing_from_the_trial_stops_ik(lab):
    t, X, labels = read_markers(fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK))
    k = labels.index("LKNE")
    write_trc(lab / "without-LKNE.trc", t, np.delete(X, k, axis=1), labels[:k] + labels[k + 1 :])
    _refused(
        lab,
        lambda: _ik(_config(lab), lab / "without-LKNE.trc"),
        [
            "without-LKNE.trc with ",
            "generic.osim: marker(s) ['LKNE'] of the model's marker set are missing",
            "markers.label_map",
            "ik.marker_weights",
            "ik.ik_tasks",
        ],
    )


def _other_subject(folder: Path, height_m: float, mass_kg: float, seed: int = 5) -> None:
    """A static trial and a walking trial of another subject (``height_m`` tall), written as the simulated lab
    writes R01's, into ``folder``."""
    from loper_analysis.device.controller import DeviceParameters
    from loper_analysis.motion.model import build_lower_body_model, segment_parameters_from_model
    from loper_analysis.synthetic.trials import (
        LabSettings,
        simulate_walking_trial,
        subject_static_recording,
        walking_recording,
    )

    lab, model = LabSettings(), build_lower_body_model(height_m, mass_kg)
    folder.mkdir(parents=True, exist_ok=True)
    write_recording(folder / "static.c3d", subject_static_recording("R02", height_m, mass_kg, 2.0, lab, seed))
    walk = simulate_walking_trial(
        8.0,
        lab,
        seed,
        height_m,
        segment_parameters_from_model(model),
        timing_cv=0.03,
        amplitude_cv=0.05,
        device=DeviceParameters(),
    )
    write_recording(folder / f"{WALK}.c3d", walking_recording(model, walk, mass_kg, lab, seed + 10))


@pytest.mark.parametrize(
    ("height_m", "refused"), [(1.55, True), (1.62, False)], ids=["11-percent-smaller", "7-percent-smaller"]
)
def test_a_walking_trial_of_another_subject_is_refused_or_warned_by_its_marker_geometry(
    lab, tmp_path, height_m, refused, caplog
):
    _other_subject(tmp_path / "R02", height_m, 50.0)
    cfg = _config(lab)
    out = tmp_path / "R02.trc"
    marker_steps.markers(
        tmp_path / "R02" / f"{WALK}.c3d", out, tmp_path / "R02.gaps.tsv", stage_settings(cfg, "markers")
    )
    static = fill(PATHS.markers.trc, subject=SUBJECT, trial="static")  # R01's, the reference
    if refused:
        message = _refused(lab, lambda: _ik(cfg, out, static), [f"{out} with ", "ik.geometry_stop_change 0.08"])
        change = float(re.search(rf"differ from the same pairs in the static trial {static} by ([\d.]+) %", message)[1])
        assert 9.0 < change < 13.0
        assert re.search(r"ratio 0\.8[6-9]\d", message) and re.search(r"\w+-\w+ \(\w+\) \d+ mm against \d+", message)
        return
    summary = tmp_path / "ik.tsv"
    ik.ik_trial(
        fill(PATHS.model.generic, subject=SUBJECT),
        out,
        tmp_path / "R02.mot",
        tmp_path / "R02.angles.tsv",
        stage_settings(cfg, "ik"),
        summary_tsv=summary,
        static_trc=static,
    )
    row = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert 0.05 < row["marker_geometry_change"] < 0.08
    assert "ik.geometry_warn_change 0.05" in row["warnings"]
    assert any("ik.geometry_warn_change" in r.getMessage() for r in caplog.records if r.levelname == "WARNING")


def test_a_model_given_as_it_is_warns_about_another_subjects_geometry_and_stops_on_a_unit(lab, tmp_path):
    """A model_osim of the subject sheet may carry its markers elsewhere than on the subject: a warning; a
    factor of 1000 between the distances is a unit, a stop whatever the model."""
    _other_subject(tmp_path / "R02", 1.55, 50.0)
    cfg = _config(lab)
    out = tmp_path / "R02.trc"
    marker_steps.markers(
        tmp_path / "R02" / f"{WALK}.c3d", out, tmp_path / "R02.gaps.tsv", stage_settings(cfg, "markers")
    )
    given = dataclasses.replace(stage_settings(cfg, "ik"), subjects_model=False)
    summary = tmp_path / "ik.tsv"
    model = fill(PATHS.model.generic, subject=SUBJECT)
    ik.ik_trial(model, out, tmp_path / "a.mot", tmp_path / "a.angles.tsv", given, summary_tsv=summary)
    row = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert row["marker_geometry_change"] > 0.08 and "ik.geometry_warn_change 0.05" in row["warnings"]
    t, X, labels = read_markers(out)
    write_trc(tmp_path / "km.trc", t, 1000.0 * X, labels)
    message = _refused(
        lab, lambda: ik.ik_trial(model, tmp_path / "km.trc", tmp_path / "b.mot", tmp_path / "b.angles.tsv", given), []
    )
    assert "times the model's: markers in another length unit" in message


def test_own_walking_trial_keeps_its_geometry(lab, tmp_path):
    summary = tmp_path / "ik.tsv"
    ik.ik_trial(
        fill(PATHS.model.generic, subject=SUBJECT),
        fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK),
        tmp_path / "own.mot",
        tmp_path / "own.angles.tsv",
        stage_settings(_config(lab), "ik"),
        summary_tsv=summary,
    )
    row = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert row["marker_geometry_change"] < 0.005 and "geometry" not in row["warnings"]
    # and against its own static trial, as the workflow compares it
    ik.ik_trial(
        fill(PATHS.model.generic, subject=SUBJECT),
        fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK),
        tmp_path / "own.mot",
        tmp_path / "own.angles.tsv",
        stage_settings(_config(lab), "ik"),
        summary_tsv=summary,
        static_trc=fill(PATHS.markers.trc, subject=SUBJECT, trial="static"),
    )
    row = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert row["marker_geometry_change"] < 0.005 and "geometry" not in row["warnings"]


def test_a_static_trial_of_another_subject_stops_the_walking_trials_ik(lab, tmp_path):
    """Another subject's static trial scales the model to that subject; the subject's own walking trial then
    differs from it and IK stops, naming the trial and the setting; the earlier results stay as they were."""
    _other_subject(tmp_path / "R02", 1.55, 50.0)
    shutil.copy(tmp_path / "R02" / "static.c3d", lab / RAW / "static.c3d")
    before = {k: v for k, v in _state(lab).items() if k in GOOD_TARGETS and "static" not in k}
    res = _snakemake(lab, fill(PATHS.ik.mot, subject=SUBJECT, trial=WALK))
    assert res.returncode != 0
    message = res.stdout + res.stderr
    trc, model = fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK), fill(PATHS.model.scaled, subject=SUBJECT)
    assert f"{trc} with {model}" in message
    assert (
        f"differ from the same pairs in the static trial {fill(PATHS.markers.trc, subject=SUBJECT, trial='static')}"
        in message
    )
    assert "ik.geometry_stop_change 0.08" in message
    after = _state(lab)
    assert {k: after[k] for k in before} == before
    assert not (lab / fill(PATHS.ik.mot, subject=SUBJECT, trial=WALK)).exists()


def test_a_static_trial_far_from_the_subjects_height_stops_scaling(lab, tmp_path):
    from loper_analysis.stages.model import step as model

    _other_subject(tmp_path / "R02", 1.25, 30.0)
    static = tmp_path / "static.trc"
    marker_steps.markers(
        tmp_path / "R02" / "static.c3d",
        static,
        tmp_path / "static.gaps.tsv",
        stage_settings(_config(lab), "markers").for_static(),
    )
    message = _refused(
        lab,
        lambda: model.scale(
            model.ScaleFiles(
                fill(PATHS.model.generic, subject=SUBJECT), static, fill(PATHS.model.scaled, subject=SUBJECT)
            ),
            MASS_KG,
            height_m=HEIGHT_M,
        ),
        [
            f"{static}: the model scaled to this static trial stands ",
            f"where the subject's height is {HEIGHT_M:.2f} m (given;",
            "height_m",
        ],
    )
    assert float(re.search(r"stands ([\d.]+) m tall", message)[1]) == pytest.approx(1.25, abs=0.06)


def test_frames_with_fewer_than_three_markers_are_left_out_and_a_trial_without_any_stops(lab, tmp_path):
    t, X, labels = read_markers(fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK))
    X[100:103, 2:] = np.nan  # frames 100-102 keep RASI and LASI only: left out, the rest solved
    write_trc(tmp_path / "sparse.trc", t, X, labels)
    o = _config(lab)["ik"]
    angles = ik.ik_trial(
        fill(PATHS.model.generic, subject=SUBJECT),
        tmp_path / "sparse.trc",
        tmp_path / "sparse.mot",
        tmp_path / "sparse.angles.tsv",
        IKSettings(coordinate_map=o["coordinate_map"]),
        summary_tsv=tmp_path / "sparse.ik.tsv",
    )
    blank = angles.drop(columns="time_s").isna().all(axis=1).to_numpy()
    assert np.flatnonzero(blank).tolist() == [100, 101, 102] and not angles.iloc[99:104:4].isna().any().any()
    summary = pd.read_csv(tmp_path / "sparse.ik.tsv", sep="\t").iloc[0]
    assert (summary.n_frames, summary.n_frames_left_out) == (len(t), 3)
    X[:, 2:] = np.nan  # no frame holds 3 markers: nothing to solve, nothing written
    write_trc(lab / "none.trc", t, X, labels)
    _refused(
        lab,
        lambda: _ik(_config(lab), lab / "none.trc"),
        [
            f"none.trc with {fill(PATHS.model.generic, subject=SUBJECT)}: {len(t)} frame(s) hold fewer than 3 of the "
            f"36 weighted markers",
            f"frames 0..{len(t) - 1}",
            "RPSI, LPSI",
        ],
    )


def test_long_gap_is_left_missing_and_counted_not_refused(lab, tmp_path):
    """Not an error: 60 missing frames of LKNE (limit 10) stay missing in the TRC and are counted."""
    rec = read_c3d(lab / RAW / f"{WALK}.c3d")
    X = rec.markers_m.copy()
    j = rec.marker_labels.index("LKNE")
    X[300:360, j] = np.nan
    write_recording(tmp_path / "gap.c3d", replace(rec, markers_m=X))
    m = _config(lab)["markers"]
    marker_steps.markers(
        tmp_path / "gap.c3d",
        tmp_path / "gap.trc",
        tmp_path / "gap.gaps.tsv",
        MarkerSettings(
            rotation_deg=m["lab_to_model_rotation_deg"], max_gap_frames=m["max_gap_frames"], walking_direction="fixed"
        ),
        summary_out=tmp_path / "gap.markers.tsv",
    )
    summary = pd.read_csv(tmp_path / "gap.markers.tsv", sep="\t").set_index("marker")
    assert summary.loc["LKNE", ["n_missing_frames", "longest_gap_frames"]].tolist() == [60, 60]
    assert (summary.drop(index="LKNE").n_missing_frames == 0).all()
    _, trc, labels = read_markers(tmp_path / "gap.trc")
    assert np.isnan(trc[300:360, labels.index("LKNE")]).all() and np.isfinite(np.delete(trc, j, axis=1)).all()


def test_missing_analog_channels_are_refused(lab):
    cfg = _config(lab)
    _refused(
        lab,
        lambda: _events(cfg, {"left": "Fz_belt3", "right": "Fz_right"}),
        [f"{RAW}/{WALK}.c3d: no analog channel 'Fz_belt3'", "channels present: Fx_left, Fz_left"],
    )
    rec = read_c3d(lab / RAW / f"{WALK}.c3d")
    i = rec.analog_labels.index("sync")
    write_recording(
        lab / "no-sync.c3d",
        replace(
            rec, analog_labels=rec.analog_labels[:i], analog_units=rec.analog_units[:i], analogs=rec.analogs[:, :i]
        ),
    )
    _refused(lab, lambda: _loadcell(cfg, c3d="no-sync.c3d"), ["no-sync.c3d: no analog channel 'sync'"])


def test_belt_channels_swapped_are_refused_from_the_heel_markers(lab):
    """The heel markers in the same file say which foot stands on each belt: the standing heel is the lower."""
    _refused(
        lab,
        lambda: _events(_config(lab), {"left": "Fz_right", "right": "Fz_left"}),
        [
            f"{RAW}/{WALK}.c3d: events.grf_channels.left: channel Fz_right does not carry the left foot: in 4 of "
            "its 4 stances the right heel (RHEE) was the lower at mid-stance",
            "events.grf_channels: {left: Fz_right, right: Fz_left}",
        ],
    )
    # both names on one belt: the right side's stances are the left foot's
    _refused(
        lab,
        lambda: _events(_config(lab), {"left": "Fz_left", "right": "Fz_left"}),
        ["events.grf_channels.right: channel Fz_left does not carry the right foot"],
    )


def test_heel_markers_given_for_the_other_feet_are_refused(lab):
    """The left heel lies right of the right heel along the pelvis's right axis: every contact would change side."""
    cfg = _config(lab)
    settings = dataclasses.replace(stage_settings(cfg, "events").events, foot_markers={"left": "RHEE", "right": "LHEE"})
    _refused(
        lab,
        lambda: event_steps.events(
            f"{RAW}/{WALK}.c3d",
            fill(PATHS.events.events, subject=SUBJECT, trial=WALK),
            settings,
            contacts_out=fill(PATHS.events.contacts, subject=SUBJECT, trial=WALK),
        ),
        [
            f"{RAW}/{WALK}.c3d: events.foot_markers (--feet) left RHEE, right LHEE: the heel given for the left foot "
            "lies ",
            "mm to the right of the one given for the right foot",
            "(here perhaps left LHEE, right RHEE)",
        ],
    )


def test_a_walk_stored_backwards_is_warned_about_by_the_events_step(lab, tmp_path):
    """Frames in reverse time: every belt stance ends with the toe risen more than the heel, as a landing does."""
    rec = read_c3d(lab / RAW / f"{WALK}.c3d")
    backward = tmp_path / "backward.c3d"
    write_recording(backward, replace(rec, markers_m=rec.markers_m[::-1].copy(), analogs=rec.analogs[::-1].copy()))
    settings = stage_settings(_config(lab), "events").events
    before = _state(lab)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)  # the trial as recorded: not a word
        event_steps.events(f"{RAW}/{WALK}.c3d", tmp_path / "forward.tsv", settings)
    with pytest.warns(UserWarning, match="time seems to run backwards in this file") as said:
        event_steps.events(backward, tmp_path / "backward.tsv", settings)
    (message,) = [str(w.message) for w in said if "backwards" in str(w.message)]
    assert message.startswith(f"{backward}: time seems to run backwards in this file: 8 of its 8 foot contact(s) ")
    assert "export the trial forward" in message
    assert _state(lab) == before


def _belts_in(lab: Path, path: Path, unit: str, factor: float) -> Path:
    """The trial with its vertical belt channels written in ``unit`` (values times ``factor``)."""
    rec = read_c3d(lab / RAW / f"{WALK}.c3d")
    belts = [rec.analog_labels.index(name) for name in ("Fz_left", "Fz_right")]
    analogs, units = rec.analogs.copy(), list(rec.analog_units)
    for i in belts:
        analogs[:, i] *= factor
        units[i] = unit
    write_recording(path, replace(rec, analogs=analogs, analog_units=units))
    return path


def test_belt_channels_in_kn_give_the_same_events_and_in_mv_are_refused(lab, tmp_path):
    cfg = _config(lab)
    e = cfg["events"]
    settings = dataclasses.replace(stage_settings(cfg, "events").events, grf_channels=e["grf_channels"])
    kn = _belts_in(lab, tmp_path / "kn.c3d", "kN", 1e-3)
    table = event_steps.events(kn, tmp_path / "e.tsv", settings)
    good = pd.read_csv(fill(PATHS.events.events, subject=SUBJECT, trial=WALK), sep="\t")
    assert len(table) == len(good) and np.allclose(table["time_s"], good["time_s"])
    mv = _belts_in(lab, tmp_path / "mv.c3d", "mV", 20.0)
    with pytest.raises(LoperInputError) as err:
        event_steps.events(mv, tmp_path / "m.tsv", settings)
    assert f"{mv}: analog channel 'Fz_left' (events.grf_channels.left) is in 'mV' (ANALOG:UNITS)" in str(err.value)
    assert not (tmp_path / "m.tsv").exists()


def test_belts_feet_that_cannot_be_confirmed_are_warned(lab, tmp_path):
    rec = read_c3d(lab / RAW / f"{WALK}.c3d")
    keep = [i for i, name in enumerate(rec.marker_labels) if name not in ("LHEE", "RHEE")]
    write_recording(
        tmp_path / "no-heels.c3d",
        replace(rec, markers_m=rec.markers_m[:, keep], marker_labels=[rec.marker_labels[i] for i in keep]),
    )
    cfg = _config(lab)
    e = cfg["events"]
    with pytest.warns(UserWarning, match="the belts' feet could not be confirmed: heel marker.s. LHEE, RHEE"):
        table = event_steps.events(
            tmp_path / "no-heels.c3d",
            tmp_path / "e.tsv",
            EventSettings(grf_channels=e["grf_channels"], foot_markers=e["foot_markers"]),
        )
    good = pd.read_csv(fill(PATHS.events.events, subject=SUBJECT, trial=WALK), sep="\t")
    assert len(table) == len(good) and np.allclose(table["time_s"], good["time_s"])


# --------------------------------------------------------------------------- robot logs


def _log_lines(work: Path) -> list[str]:
    return (work / RAW / f"{WALK}.loper.tsv").read_text().splitlines(keepends=True)


def _without_column(lines: list[str], col: int) -> list[str]:
    return [ln if ln.startswith("#") else "\t".join(np.delete(ln.rstrip("\n").split("\t"), col)) + "\n" for ln in lines]


def _nan_at(lines: list[str], line: int, col: int) -> list[str]:
    cells = lines[line].rstrip("\n").split("\t")
    cells[col] = "nan"
    return [*lines[:line], "\t".join(cells) + "\n", *lines[line + 1 :]]


@pytest.mark.parametrize(
    ("name", "damage", "words"),
    [
        (
            "missing column",
            lambda ls: _without_column(ls, 1),
            ["missing column(s) force_desired_n", "a robot log has the columns time_s, force_desired_n"],
        ),
        (
            "unordered time",
            lambda ls: [*ls[:10], ls[11], ls[10], *ls[12:]],
            ["column 'time_s', sample 7 (t = 0.006 s, line 12): time not strictly increasing"],
        ),
        (
            "NaN",
            lambda ls: _nan_at(ls, 20, 2),
            ["column 'force_measured_n', sample 16 (t = 0.016 s, line 21): non-finite force nan"],
        ),
        (
            "wrong rate",
            lambda ls: [ln.replace("# sample_rate_hz: 1000", "# sample_rate_hz: 500") for ln in ls],
            ["column 'time_s', sample 1", "deviates -50 % from 1/sample_rate_hz = 2 ms"],
        ),
        (
            "cut line",
            lambda ls: [*ls[:5000], ls[5000][:20]],
            ["sample 4996 (line 5001): 4 field(s), expected 8 (one per column)"],
        ),
    ],
    ids=["missing-column", "unordered-time", "nan", "wrong-rate", "cut-line"],
)
def test_bad_robot_log_is_refused_by_the_loadcell_step(lab, name, damage, words):
    path = lab / RAW / f"{WALK}.loper.tsv"
    path.write_text("".join(damage(_log_lines(lab))))
    _refused(lab, lambda: _loadcell(_config(lab)), [f"{RAW}/{WALK}.loper.tsv: ", *words])


def test_robot_log_of_another_trial_is_refused(lab):
    _refused(
        lab,
        lambda: _loadcell(_config(lab), log=f"elsewhere/{WALK}.loper.tsv"),
        [
            f"elsewhere/{WALK}.loper.tsv / {RAW}/{WALK}.c3d: no 4 consecutive sync edges of the robot log",
            "(10 edges)",
            "of the mocap record (8 edges)",
        ],
    )


def test_bad_robot_log_of_a_new_trial_stops_its_job_with_one_line_and_a_log(lab):
    """Through Snakemake: a new perturbation trial whose log holds a NaN."""
    # another recording (the same walk recorded at another time: one recording stands for one trial)
    shutil.copy(lab / "elsewhere" / f"{WALK}.c3d", lab / RAW / "pert050-1.c3d")
    (lab / RAW / "pert050-1.loper.tsv").write_text("".join(_nan_at(_log_lines(lab), 20, 2)))
    _refused(
        lab,
        lambda: _snakemake(lab, fill(PATHS.events.force, subject=SUBJECT, trial="pert050-1")),
        [
            (
                f"{RAW}/pert050-1.loper.tsv: column 'force_measured_n', sample 16 (t = 0.016 s, line 21): "
                "non-finite force nan"
            )
        ],
        log=PATHS.log("events_loadcell", f"{SUBJECT}/pert050-1"),
    )


# --------------------------------------------------------------------------- subjects and config (before any work)


def test_recorded_subject_without_a_static_trial_is_refused(lab):
    (lab / "config/subjects.tsv").write_text(
        f"subject\tsource\theight_m\tmass_kg\n{SUBJECT}\trecorded\t1.75\t70\nR02\trecorded\t1.6\t55\n"
    )
    (lab / "data/raw/R02").mkdir()
    shutil.copy(lab / RAW / f"{WALK}.c3d", lab / "data/raw/R02" / f"{WALK}.c3d")
    _refused(
        lab,
        lambda: _snakemake(lab, "-n"),
        ["config/subjects.tsv: recorded subject 'R02' has no static trial data/raw/R02/static.c3d"],
    )


@pytest.mark.parametrize(
    ("make", "words"),
    [
        (
            lambda path: path.symlink_to("/mnt/lab-share/R01/pert050-1.c3d"),
            ["is a broken link (to '/mnt/lab-share/R01/pert050-1.c3d')"],
        ),
        (lambda path: path.mkdir(), ["is a directory; a trial's raw file must be a file"]),
    ],
    ids=["broken-link", "directory"],
)
def test_trial_path_that_is_not_a_file_stops_the_run_naming_it(lab, make, words):
    """Not "no such trial": the fit would silently use the other trials of the onset."""
    make(lab / RAW / "pert050-1.c3d")
    _refused(
        lab,
        lambda: _snakemake(lab, "-n"),
        [f"{RAW}/pert050-1.c3d: the raw file of trial 'pert050-1' of subject '{SUBJECT}' ", *words],
    )


def test_raw_files_that_match_no_trial_of_the_design_are_named_in_a_warning(lab):
    shutil.copy(lab / RAW / f"{WALK}.c3d", lab / RAW / "pert100-1.c3d")  # onsets of the design: 50 ms only
    (lab / RAW / "pert100-1.loper.tsv").write_text("")
    before = _state(lab)
    res = _snakemake(lab, "-n", PATHS.strides.summary)
    assert res.returncode == 0, res.stdout[-2000:]
    assert (
        f"warning: {RAW}: pert100-1.c3d, pert100-1.loper.tsv: no trial of the design has this name, not "
        "analysed (trials: static, walk-nodevice, walk-device, pert050-1, device-frf, device-steps; "
    ) in res.stderr
    assert "study.perturbation_onsets_ms [50] and study.perturbation_repeats 1" in res.stderr
    assert _state(lab) == before


@pytest.mark.parametrize("trial", [WALK, "device-frf"])
def test_two_robot_logs_of_one_trial_stop_the_run_naming_both(lab, trial):
    """A .loper.tsv beside a .mat of the same trial, whatever its kind: one would be read and the other ignored."""
    from scipy.io import savemat

    if trial != WALK:  # a log of its own (a copy of another trial's would be refused as that)
        lines = (lab / RAW / f"{WALK}.loper.tsv").read_text().splitlines(keepends=True)
        (lab / RAW / f"{trial}.loper.tsv").write_text("".join(lines[: len(lines) // 2]))
    savemat(lab / RAW / f"{trial}.mat", {"force": np.zeros((4, 2))})
    _refused(
        lab,
        lambda: _snakemake(lab, "-n"),
        [
            f"{RAW}/{trial}.loper.tsv and {RAW}/{trial}.mat: two robot logs of trial '{trial}' of subject '{SUBJECT}'",
            f"keep one and move the other out of {RAW}",
        ],
    )


@pytest.mark.parametrize("name", [f"{WALK}.C3D", f"{WALK}.Loper.tsv"])
def test_a_raw_file_named_in_another_case_stops_the_run_naming_it(lab, name):
    """An export's upper-case suffix: on a case-sensitive file system the trial would be left out without a word."""
    right = name.split(".", 1)[0] + "." + name.split(".", 1)[1].lower()
    (lab / RAW / right).rename(lab / RAW / name)
    _refused(
        lab,
        lambda: _snakemake(lab, "-n"),
        [f"{RAW}/{name}: the raw file of trial '{WALK}' is named '{name}'", f"rename it '{right}'"],
    )


def test_a_raw_file_replaced_with_its_old_time_kept_is_processed_again(lab):
    """``cp -p`` of another recording over a raw file keeps a time older than the results: the content
    checksum (a param of every rule that reads raw files) reruns what was made from it, and only that."""
    import os

    trc = lab / fill(PATHS.markers.trc, subject=SUBJECT, trial=WALK)
    static_trc = lab / fill(PATHS.markers.trc, subject=SUBJECT, trial="static")
    old_trc, old_static = trc.read_bytes(), static_trc.read_bytes()
    assert "Nothing to be done" in _snakemake(lab, "-n", *GOOD_TARGETS).stdout
    raw = lab / RAW / f"{WALK}.c3d"
    for name in (f"{WALK}.c3d", f"{WALK}.loper.tsv"):  # the trial recorded again, both files copied as cp -p does
        then = (lab / RAW / name).stat().st_mtime_ns
        shutil.copyfile(lab / "elsewhere" / name, lab / RAW / name)
        os.utime(lab / RAW / name, ns=(then, then))
    assert raw.stat().st_mtime_ns < trc.stat().st_mtime_ns
    dry = _snakemake(lab, "-n", *GOOD_TARGETS)
    assert dry.returncode == 0, dry.stderr[-2000:]
    assert "Rules with provenance triggered jobs: events_loadcell markers\n" in dry.stdout, dry.stdout[-3000:]
    assert re.search(r"^total\s+2$", dry.stdout, re.M), dry.stdout[-3000:]
    res = _snakemake(lab, *GOOD_TARGETS)
    assert res.returncode == 0, res.stderr[-2000:]
    assert trc.read_bytes() != old_trc and static_trc.read_bytes() == old_static
    assert "Nothing to be done" in _snakemake(lab, "-n", *GOOD_TARGETS).stdout


def test_a_robot_log_that_ends_half_way_sets_the_trials_status_and_says_so_on_the_console(lab):
    cfg = _config(lab)
    cfg["strides"]["min_valid_strides"] = 3  # an 8-s trial
    (lab / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    summary = lab / PATHS.strides.summary
    res = _snakemake(lab, PATHS.strides.summary)
    assert res.returncode == 0, res.stderr[-3000:]
    whole = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    assert whole["status"] == "ok" and whole["n_outside_robot_log"] == 0
    log = lab / RAW / f"{WALK}.loper.tsv"
    lines = log.read_text().splitlines(keepends=True)
    header = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#")]
    log.write_text("".join(header + body[: len(body) // 2 + 1]))  # the header line and the first half
    res = _snakemake(lab, PATHS.strides.summary)
    assert res.returncode == 0, res.stderr[-3000:]
    cut = pd.read_csv(summary, sep="\t", keep_default_na=False).iloc[0]
    n_with_events = cut["n_strides"] + cut["n_outside_robot_log"]
    assert cut["status"] == "log_truncated"
    assert n_with_events == whole["n_strides"] and cut["outside_robot_log_fraction"] > 0.3
    said = f"robot log truncated? {cut['n_outside_robot_log']} of the strides with events"
    assert said in cut["warnings"]
    assert f"{SUBJECT} {WALK}: log_truncated; {said}" in res.stderr  # the run's warnings on the console
    dropped = pd.read_csv(lab / fill(PATHS.strides.dropped, subject=SUBJECT, trial=WALK), sep="\t")
    assert (dropped["reason"] == "outside_robot_log").sum() == cut["n_outside_robot_log"]


def test_recorded_only_study_with_belt_channels_and_its_own_onsets_is_planned(lab):
    """Not an error: onsets without a synthetic truth (no synthetic subject), and C3D files with one force channel
    per belt instead of force platforms: events from the channels, no external loads, said in a note."""
    cfg = _config(lab)
    cfg["device"]["subject"] = None
    cfg["study"]["perturbation_onsets_ms"] = [100]  # the synthetic truth has 50, 175 and 300 ms
    (lab / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    for suffix in (".c3d", ".loper.tsv"):  # another recording of the walk (one recording stands for one trial)
        shutil.copy(lab / "elsewhere" / f"{WALK}{suffix}", lab / RAW / f"pert100-1{suffix}")
    before = _state(lab)
    res = _snakemake(lab, "-n")
    assert res.returncode == 0, res.stdout[-3000:]
    for trial in (WALK, "pert100-1"):
        assert (
            f"note: {RAW}/{trial}.c3d: no force platforms (FORCE_PLATFORM:USED 0 or absent): events from the "
            "belt channels (events.grf_channels: {'left': 'Fz_left', 'right': 'Fz_right'}), no OpenSim external "
            f"loads ({fill(PATHS.grf.mot, subject=SUBJECT, trial=trial)})"
        ) in res.stderr
    assert "rule grf:" not in res.stdout and fill(PATHS.impedance.fit, subject=SUBJECT, onset=100) in res.stdout
    assert _state(lab) == before


def test_impossible_anthropometrics_are_refused(lab):
    (lab / "config/subjects.tsv").write_text(f"subject\tsource\theight_m\tmass_kg\n{SUBJECT}\trecorded\t17.5\t70\n")
    _refused(
        lab,
        lambda: _snakemake(lab, "-n"),
        ["config/subjects.tsv: row 1, column 'height_m': 17.5 is greater than the maximum of 2.5"],
    )


def test_recorded_subject_without_some_trials_is_planned_without_them(lab):
    """Not an error: only the trials on disk are processed (the onset without a trial is reported missing;
    the full run is in tests/test_workflow.py)."""
    before = _state(lab)
    res = _snakemake(lab, "-n", PATHS.impedance.table, PATHS.strides.summary)
    assert res.returncode == 0, res.stderr[-2000:]
    trials = set(re.findall(r"^\s+wildcards: subject=R01, trial=(\S+)$", res.stdout, re.MULTILINE))
    assert trials == {WALK}  # its IK and strides: markers, events and forces are already there
    fit = re.search(r"^rule impedance_fit:$(.*?)^$", res.stdout, re.MULTILINE | re.DOTALL)  # every onset's fit
    assert fit and re.search(r"^\s+wildcards: subject=R01$", fit.group(1), re.MULTILINE)
    assert fill(PATHS.impedance.fit, subject="R01", onset=50) in fit.group(1)
    assert _state(lab) == before


@pytest.mark.parametrize(
    ("files", "args", "words"),
    [
        (
            {"config/lab.yaml": {"identification": {"n_starts": "ten"}}},
            ["--configfile", "config/lab.yaml"],
            ["config/lab.yaml: key 'impedance.n_starts': 'ten' is not of type 'integer'"],
        ),
        ({}, ["--config", "seed=-1"], ["--config: key 'seed': -1 is less than the minimum of 0"]),
        (
            {"config/lab.yaml": {"seed": 7}, "config/extra.yaml": {"validation": {"n_chunkz": 2}}},
            ["--configfile", "config/lab.yaml", "config/extra.yaml"],
            ["config/extra.yaml: key 'validation.n_chunkz': Additional properties are not allowed ('n_chunkz'"],
        ),
        (
            {"config/lab.yaml": {"filter": {"cutoff_hz": -40.0}}},
            ["--configfile", "config/lab.yaml", "--config", "seed=7"],
            ["config/lab.yaml: key 'markers.filter.cutoff_hz': -40.0"],
        ),
        (
            {"config/lab.yaml": {"identification": {"stiffness_bounds_nm_per_rad": [200.0, 0.0]}}},
            ["--configfile", "config/lab.yaml"],
            [
                "config/lab.yaml: key 'impedance.stiffness_bounds_nm_per_rad': [200.0, 0.0] is reversed or "
                "empty: give [low, high] with low below high"
            ],
        ),
        (
            {"config/lab.yaml": {"trials": {"static": "walk-nodevice"}}},
            ["--configfile", "config/lab.yaml"],
            [
                "config/lab.yaml: key 'study.static': 'walk-nodevice' is also the walking trial study.no_device: "
                "the static trial is a standing trial of its own"
            ],
        ),
        (
            {"config/lab.yaml": {"opensim": {"geometry_warn_change": 0.2}}},
            ["--configfile", "config/lab.yaml"],
            [
                "config/lab.yaml: key 'ik.geometry_warn_change' 0.2 exceeds 'ik.geometry_stop_change' 0.08 "
                "(from config/config.yaml)"
            ],
        ),
    ],
    ids=[
        "type-in-configfile",
        "range-in-config-option",
        "unknown-key-in-last-configfile",
        "configfile-under-config-option",
        "reversed-bounds",
        "static-named-as-a-walking-trial",
        "warning-above-stop",
    ],
)
def test_bad_config_names_the_file_or_option_key_and_value(lab, files, args, words):
    for name, doc in files.items():
        (lab / name).write_text(yaml.safe_dump(doc))
    _refused(lab, lambda: _snakemake(lab, "-n", *args), words)
