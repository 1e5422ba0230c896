"""End to end: the validation workflow on a tiny config, config validation, report."""

from __future__ import annotations

import ast
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.layout import fill
from loper_analysis.stages import study_paths
from tests.workflow_copy import snakemake

PATHS = study_paths()

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials (pytest -m "not slow" leaves them out)
ROOT = Path(__file__).resolve().parents[1]


def _project(tmp: Path, **changes) -> Path:
    """Copy the workflow into tmp with a small validation study (2 levels -> 64 combinations)."""
    for item in ("Snakefile", "workflow", "config"):
        src = ROOT / item
        (shutil.copytree if src.is_dir() else shutil.copy)(src, tmp / item)
    cfg = yaml.safe_load((ROOT / "config/config.yaml").read_text())
    cfg["validation"].update(
        stiffness_levels_nm_per_rad=[0.0, 150.0], damping_levels_nms_per_rad=[0.0, 4.0], n_chunks=2
    )
    cfg["impedance"]["n_starts"] = 3
    # one synthetic subject, short trials, one perturbation trial
    (tmp / "config/subjects.tsv").write_text(
        "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\n"
    )
    cfg["synthetic"]["walking_duration_s"] = 25.0
    cfg["study"].update(perturbation_onsets_ms=[50], perturbation_repeats=1)
    for key, value in changes.items():
        section, _, name = key.partition("__")
        if name:
            cfg[section][name] = value
        else:
            cfg[section] = value
    (tmp / "config/config.yaml").write_text(yaml.safe_dump(cfg, sort_keys=False))
    return tmp


def _snakemake(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    return snakemake(cwd, *args, timeout=600)


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory) -> Path:
    work = _project(tmp_path_factory.mktemp("run"))
    res = _snakemake(work)
    assert res.returncode == 0, res.stderr[-3000:]
    return work


def test_tiny_validation_recovers_truth(finished_run):
    summary = pd.read_csv(finished_run / PATHS.validation.summary, sep="\t")
    assert list(summary.columns[:5]) == ["condition", "parameter", "min_error", "max_error", "sd_error"]
    assert len(summary) == 12
    clean = summary[summary.condition == "no_noise"].set_index("parameter")
    k = [p for p in clean.index if p.startswith("K")]
    d = [p for p in clean.index if p.startswith("D")]
    assert (clean.loc[k, "max_abs_error"] <= 0.05).all(), clean
    assert (clean.loc[d, "max_abs_error"] <= 0.005).all(), clean
    errors = pd.read_csv(finished_run / PATHS.validation.errors, sep="\t")
    assert len(errors) == 64 * 2 * 6
    assert sorted(errors.combination.unique()) == list(range(64))
    np.testing.assert_allclose(errors.error, errors.estimate - errors.true, atol=1e-12)
    fits = pd.read_csv(finished_run / PATHS.validation.fits, sep="\t")
    assert len(fits) == 128 and fits.success.all()


def test_rerun_does_nothing_and_report_builds(finished_run):
    res = _snakemake(finished_run, "-n")
    assert res.returncode == 0
    assert "Nothing to be done" in res.stdout + res.stderr
    res = _snakemake(finished_run, "--report", "report.html")
    assert res.returncode == 0, res.stderr[-3000:]
    html = (finished_run / "report.html").read_bytes()
    assert len(html) > 10_000 and b"errors.png" in html and b"transparency.png" in html
    assert b"responses.png" in html and b"impedance.png" in html


def test_same_config_gives_same_bytes(finished_run, tmp_path):
    work = _project(tmp_path)
    raw = ["data/raw/S01/static.c3d", "data/raw/S01/walk-device.c3d", "data/raw/S01/walk-device.loper.tsv"]
    res = _snakemake(work, PATHS.validation.summary, *raw)
    assert res.returncode == 0, res.stderr[-3000:]
    for name in ("errors.tsv", "fits.tsv", "summary.tsv"):
        assert (work / PATHS.validation.root / name).read_bytes() == (
            finished_run / PATHS.validation.root / name
        ).read_bytes(), name
    for name in raw:
        assert (work / name).read_bytes() == (finished_run / name).read_bytes(), name


def test_processing_outputs_from_the_default_run(finished_run):
    results = finished_run / "results"
    for trial in ("walk-nodevice", "walk-device", "pert050-1"):
        strides = pd.read_csv(results / f"strides/S01/{trial}.strides.tsv", sep="\t")
        # 25 s at 36 strides/min: 13-14 complete left strides, at most 20 % removed as outliers
        assert 12 <= len(strides) <= 15 and strides.removed.sum() <= 0.2 * len(strides), trial
        np.testing.assert_allclose(strides.duration_s.mean(), 60 / 36, rtol=0.05)
    angles = pd.read_csv(results / "ik/S01/walk-device.angles.tsv", sep="\t")
    assert len(angles) == 25 * 128 and np.ptp(angles.knee_left_rad) > np.deg2rad(45)
    rmsd = pd.read_csv(results / "transparency/rmsd.tsv", sep="\t")
    assert len(rmsd) == 12 and set(rmsd.subject) == {"S01", "all"}
    # the synthetic subject walks with the device within its stride-to-stride variability
    assert rmsd.transparent.all() and (rmsd.rmsd_rad < rmsd.isv_ave_rad).all()
    force = pd.read_csv(results / "transparency/force.tsv", sep="\t").set_index(["subject", "phase"])
    for phase in ("stance", "swing"):
        row = force.loc[("S01", phase)]
        assert abs(row.rms_force_mean_n / row.study_rms_force_mean_n - 1) <= 0.3, (phase, row.rms_force_mean_n)
    assert (results / "transparency/transparency.png").stat().st_size > 20_000


def test_impedance_table_from_the_default_run(finished_run):
    """One subject, one 25 s trial at the 50 ms onset: too few perturbations to fit, reported as failed."""
    from loper_analysis.impedance.identification.impedance import IMPEDANCE_COLUMNS

    table = pd.read_csv(finished_run / PATHS.impedance.table, sep="\t")
    assert list(table.columns) == list(IMPEDANCE_COLUMNS)
    assert list(table.joint) == ["hip", "knee", "ankle"] and (table.onset_ms == 50).all()
    counts = pd.read_csv(finished_run / fill(PATHS.impedance.counts, subject="S01", onset=50), sep="\t")
    counts = counts.set_index("trial")
    # a pulse every 3-5 of ~14 strides: 3 perturbed, all matched and kept (too few for the IQR rule to judge)
    assert counts.loc["total", ["n_perturbed", "n_kept"]].tolist() == [3, 3]
    assert counts.loc["total", "status"] == "too_few_strides"
    assert (table.status == "failed").all() and table.reason.str.contains("3 valid perturbed stride").all()
    assert table.K_nm_per_rad.isna().all()
    summary = pd.read_csv(finished_run / PATHS.impedance.summary, sep="\t")
    assert len(summary) == 0 and list(summary.columns[:2]) == ["joint", "onset_ms"]  # nothing fitted
    literature = pd.read_csv(finished_run / PATHS.impedance.literature, sep="\t")
    assert len(literature) == 7 and literature.K_low_nm_per_rad.iloc[0] == 50.0
    md = (finished_run / PATHS.report.tables).read_text()
    assert "## Impedance per subject, onset and joint" in md and "| S01 | 50 | hip |" in md
    assert "## Transparency: RMSD vs ISV_ave" in md and "## Validation study" in md
    for fig in ("impedance/impedance.png", "impedance/S01/responses.png", "impedance/S01/fit.png"):
        assert (finished_run / "results" / fig).read_bytes()[:4] == b"\x89PNG", fig
    truth = yaml.safe_load((finished_run / "data/raw/S01/truth.yaml").read_text())
    np.testing.assert_allclose(
        table.K_true_nm_per_rad,
        [truth["impedance"]["onset_050_ms"][j]["stiffness_nm_per_rad"] for j in ("hip", "knee", "ankle")],
    )


@pytest.mark.parametrize(
    ("changes", "expected"),
    [
        ({"impedance__n_stars": 3}, "key 'impedance.n_stars'"),
        ({"impedance__n_starts": "ten"}, "key 'impedance.n_starts': 'ten'"),
        ({"validation__n_chunks": 0}, "key 'validation.n_chunks': 0"),
        ({"subjects": "config/nowhere.tsv"}, "key 'subjects': file 'config/nowhere.tsv' not found"),
    ],
)
def test_bad_config_is_refused_with_its_key(tmp_path, changes, expected):
    work = _project(tmp_path, **changes)
    res = _snakemake(work, "-n")
    assert res.returncode != 0
    assert f"config/config.yaml: {expected}" in res.stdout + res.stderr


@pytest.mark.parametrize(
    ("sheet", "changes", "expected"),
    [
        ("subject\tsource\theight_m\nS01\tsynthetic\t2.7\n", {}, "height_m"),
        ("subject\tsource\tmass_kg\nS01\tsynthetic\t-4\n", {}, "mass_kg"),
        (
            None,
            {
                "synthetic__stiffness_nm_per_rad": {
                    "50": [230.0, 3.0, 8.0],
                    "175": [38.0, 0.5, 8.0],
                    "300": [62.0, 2.5, 8.0],
                }
            },
            "outside the identification bounds",
        ),
        (
            "subject\tsource\theight_m\tmass_kg\nS01\tsynthetic\t1.8\t70\nR01\trecorded\t1.7\t60\n",
            {},
            "data/raw/R01/static.c3d",
        ),
    ],
)
def test_bad_subjects_are_refused_before_any_work(tmp_path, sheet, changes, expected):
    work = _project(tmp_path, **changes)
    if sheet is not None:
        (work / "config/subjects.tsv").write_text(sheet)
    res = _snakemake(work, "-n")
    assert res.returncode != 0
    assert expected in res.stdout + res.stderr
    assert not (work / "data").exists() and not (work / "results").exists()


def test_recorded_subjects_raw_files_are_never_written(tmp_path):
    work = _project(tmp_path)
    (work / "config/subjects.tsv").write_text(
        "subject\tsource\theight_m\tmass_kg\nS01\tsynthetic\t1.8\t70\nR01\trecorded\t1.7\t60\n"
    )
    raw = work / "data/raw/R01"
    raw.mkdir(parents=True)
    (raw / "static.c3d").write_bytes(b"placeholder")
    res = _snakemake(work, "-n", "data/raw/R01/walk-device.c3d")
    assert res.returncode != 0 and "MissingRuleException" in res.stdout + res.stderr
    res = _snakemake(work, "-n", "data/raw/R01/truth.yaml")
    assert res.returncode != 0


def test_bad_subject_sheet_is_refused(tmp_path):
    work = _project(tmp_path)
    (work / "config/subjects.tsv").write_text("subject\tsource\nS_01\tsynthetic\n")
    res = _snakemake(work, "-n")
    assert res.returncode != 0
    out = res.stdout + res.stderr
    assert "subjects.tsv" in out and "S_01" in out


def _rule_blocks() -> dict[str, str]:
    """{rule name: its text} of every rule in workflow/rules/*.smk."""
    blocks = {}
    for smk in sorted((ROOT / "workflow/rules").glob("*.smk")):
        parts = re.split(r"^\s*rule (\w+):\s*$", smk.read_text(), flags=re.MULTILINE)
        blocks.update(zip(parts[1::2], parts[2::2]))
    return blocks


def test_every_job_runs_its_step_inside_its_log():
    """Each rule has a log and a script (no run: or shell:); each script imports only rule_log before entering
    it, so an import error, a missing parameter or a failing step all end up in the job's log."""
    blocks = _rule_blocks()
    assert len(blocks) >= 30
    scripts = set()
    for name, body in blocks.items():
        assert re.search(r"^\s+log:\s*$", body, re.MULTILINE), name
        assert not re.search(r"^\s+(run|shell):", body, re.MULTILINE), name
        scripts.add(re.search(r'^\s+script:\s*\n\s+"\.\./scripts/(\w+\.py)"', body, re.MULTILINE).group(1))
    assert scripts == {p.name for p in (ROOT / "workflow/scripts").glob("*.py")}
    for name in scripts:
        tree = ast.parse((ROOT / "workflow/scripts" / name).read_text())
        first, second, *rest = tree.body
        assert ast.unparse(first) == "from loper_analysis.stages import rule_log", name
        assert isinstance(second, ast.With) and not rest, name
        assert ast.unparse(second.items[0].context_expr) == "rule_log(snakemake.log[0])", name
        step = second.body[0]  # the stage's file step: from loper_analysis.stages.<stage> import step as ...
        assert isinstance(step, ast.ImportFrom) and step.module.startswith("loper_analysis.stages."), name
        assert [a.name for a in step.names] == ["step"], name


def test_a_failed_job_leaves_its_message_and_traceback_in_its_log(tmp_path):
    """A truncated C3D: the console shows the cause in one line, the job's log the message and the traceback."""
    work = _project(tmp_path, device__subject="R01")
    (work / "config/subjects.tsv").write_text("subject\tsource\theight_m\tmass_kg\nR01\trecorded\t1.8\t72\n")
    raw = work / "data/raw/R01"
    raw.mkdir(parents=True)
    (raw / "static.c3d").write_bytes((ROOT / "tests/data/opensim-core/walking5.c3d").read_bytes()[:30_000])
    res = _snakemake(work, fill(PATHS.markers.trc, subject="R01", trial="static"))
    assert res.returncode != 0
    message = "data/raw/R01/static.c3d: truncated file: the header declares 1103 frames but only 22 could be read"
    console = res.stdout + res.stderr
    assert console.count(message) == 1 and "Traceback" not in console
    assert f"{PATHS.log('markers', 'R01/static')} (check log file(s) for error details)" in console
    log = (work / PATHS.log("markers", "R01/static")).read_text()
    assert f"ERROR loper_analysis.rule: LoperInputError: {message}" in log
    assert "Traceback (most recent call last)" in log and "in read_c3d" in log
    assert log.rstrip().endswith(f"loper_analysis.errors.LoperInputError: {message}")
    assert not (work / PATHS.markers.root).exists()  # nothing half-written


def test_device_outputs_from_the_default_run(finished_run):
    summary = pd.read_csv(finished_run / PATHS.device.summary, sep="\t").set_index("metric")
    assert list(summary.columns[:3]) == ["value", "study_value", "unit"]
    for metric in ("bandwidth_hz", "rise_time_ms", "overshoot_pct", "steady_state_40n_n"):
        assert abs(summary.loc[metric, "value"] / summary.loc[metric, "study_value"] - 1) <= 0.15, metric
    frf = pd.read_csv(finished_run / PATHS.device.frf, sep="\t")
    assert list(frf.columns) == ["frequency_hz", "gain", "phase_deg", "coherence"]
    steps = pd.read_csv(finished_run / PATHS.device.step_metrics, sep="\t")
    assert list(steps.amplitude_n) == [20.0, 40.0, 60.0] and (steps.n_repetitions == 10).all()
    # the logs the analysis read are on disk, in the robot-log format
    head = (finished_run / "data/raw/S01/device-steps.loper.tsv").read_text().splitlines()[:2]
    assert head == ["# format: loper-log 1", "# sample_rate_hz: 1000"]


def test_recorded_subject_without_a_trial_reports_that_onset_missing(finished_run, tmp_path):
    """A recorded subject whose only perturbation trial is absent: the run completes, its rows say missing."""
    work = _project(tmp_path, device__subject="R01")
    (work / "config/subjects.tsv").write_text("subject\tsource\theight_m\tmass_kg\nR01\trecorded\t1.8\t72\n")
    raw = work / "data/raw/R01"
    raw.mkdir(parents=True)
    for name in ("static.c3d", "walk-nodevice.c3d", "walk-device.c3d", "walk-device.loper.tsv"):
        shutil.copy(finished_run / "data/raw/S01" / name, raw / name)
    res = _snakemake(work, PATHS.impedance.table)
    assert res.returncode == 0, res.stderr[-3000:]
    table = pd.read_csv(work / PATHS.impedance.table, sep="\t")
    assert list(table.joint) == ["hip", "knee", "ankle"] and (table.subject == "R01").all()
    assert (table.status == "missing").all() and (table.reason == "no trial of this onset").all()
    assert table[["K_nm_per_rad", "D_nms_per_rad", "K_true_nm_per_rad", "D_true_nms_per_rad"]].isna().all().all()
    assert not (work / PATHS.ik.root).exists()  # nothing was processed for an onset without trials


def _copy_of(project: Path, dest: Path) -> Path:
    """A copy of a finished project with its files' times and Snakemake's records: only what changes reruns."""
    shutil.copytree(project, dest, symlinks=True)
    return dest


def _cut_c3d(path: Path, seconds: float) -> None:
    """Keep the first ``seconds`` of a synthetic subject's C3D (markers and analogs), as a recording stopped early;
    written as the synthetic lab's own (its manifest vouches for the new content)."""
    from dataclasses import replace

    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.c3d_writer import write_recording
    from loper_analysis.io.generated import generated

    rec = read_c3d(path)
    n = round(seconds * rec.point_rate_hz)
    cut = {
        "markers_m": rec.markers_m[:n],
        "outputs": rec.outputs[:n],
        "analogs": rec.analogs[: n * rec.samples_per_frame],
    }
    with generated(path, "synthetic_lab", "C3D file") as tmp:
        write_recording(tmp, replace(rec, **cut))


def test_trials_with_too_few_strides_are_flagged_and_the_run_goes_on(finished_run, tmp_path):
    """walk-device and pert050-1 cut to 5 s (2 complete left strides each, no perturbation yet): warnings and
    flagged rows, transparency without the subject, the fit failed with its reason; the run ends normally."""
    work = _copy_of(finished_run, tmp_path / "short")
    for trial in ("walk-device", "pert050-1"):
        _cut_c3d(work / f"data/raw/S01/{trial}.c3d", 5.0)
    res = _snakemake(work)
    assert res.returncode == 0, res.stderr[-3000:]
    summary = pd.read_csv(work / PATHS.strides.summary, sep="\t").set_index("trial")
    assert summary.loc["walk-nodevice", "status"] == "ok"
    for trial in ("walk-device", "pert050-1"):
        assert summary.loc[trial, ["n_strides", "n_kept", "status"]].tolist() == [2, 2, "too_few_strides"], trial
        strides = pd.read_csv(work / fill(PATHS.strides.strides, subject="S01", trial=trial), sep="\t")
        assert len(strides) == 2 and not strides.removed.any()
        assert strides.filter(like="fraction_outlying_").isna().all().all()
        log = (work / PATHS.log("strides", f"S01/{trial}")).read_text()
        assert "2 complete unperturbed left stride(s)" in log and "the outlier rule needs at least 4" in log
    rmsd = pd.read_csv(work / PATHS.transparency.rmsd, sep="\t")
    assert len(rmsd) == 12 and (rmsd.n_strides_device == [2] * 6 + [0] * 6).all()
    assert rmsd[["rmsd_rad", "isv_ave_rad", "transparent"]].isna().all().all()
    assert "subject S01: " in (work / PATHS.log("transparency", "transparency")).read_text()
    table = pd.read_csv(work / PATHS.impedance.table, sep="\t")
    assert (table.status == "failed").all() and table.reason.str.startswith("0 valid perturbed stride(s)").all()
    counts = pd.read_csv(work / fill(PATHS.impedance.counts, subject="S01", onset=50), sep="\t").set_index("trial")
    assert counts.loc["total", ["n_perturbed", "status"]].tolist() == [0, "too_few_strides"]


def test_a_killed_run_recovers_to_the_bytes_of_an_uninterrupted_one(finished_run, tmp_path):
    """The README's recovery: kill the whole run (SIGKILL) after some jobs, `--unlock`, `--rerun-incomplete`."""
    import os
    import signal
    import time

    work = _copy_of(finished_run, tmp_path / "killed")
    later = time.time() + 1
    os.utime(work / "data/raw/S01/pert050-1.c3d", (later, later))  # a newer raw trial: its processing reruns
    console = tmp_path / "killed.out"
    with console.open("w") as out:
        run = subprocess.Popen(
            [sys.executable, "-m", "snakemake", "--cores", "2"],
            cwd=work,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        deadline = time.monotonic() + 300
        while run.poll() is None and console.read_text().count("Finished jobid") < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        os.killpg(run.pid, signal.SIGKILL)
        run.wait()
    text = console.read_text()
    n_jobs = int(re.search(r"^total\s+(\d+)$", text, re.MULTILINE).group(1))
    assert 3 <= text.count("Finished jobid") < n_jobs - 3  # killed halfway
    assert "locked" in (_snakemake(work).stderr + "").lower()  # the lock stays until --unlock
    assert _snakemake(work, "--unlock").returncode == 0
    res = _snakemake(work, "--rerun-incomplete")
    assert res.returncode == 0, res.stderr[-3000:]
    assert not list((work / "results").rglob("*.partial"))  # no staging left behind

    def tables(root: Path) -> dict:
        return {
            p.relative_to(root): p.read_bytes()
            for p in (root / "results").rglob("*.tsv")
            if "benchmarks" not in p.parts
        }  # job timings differ by nature

    ours, clean = tables(work), tables(finished_run)
    assert sorted(ours) == sorted(clean) and len(ours) >= 40
    assert [str(p) for p in ours if ours[p] != clean[p]] == []


def _dry_run_rules(work: Path, *args: str) -> dict[str, set[str]]:
    """Rules a dry run would run, with the trials of their jobs (empty set for jobs without a trial)."""
    import re

    res = _snakemake(work, "-n", *args)
    assert res.returncode == 0, res.stderr[-3000:]
    blocks = re.split(r"^\s*(?:local)?rule (\w+):$", res.stdout, flags=re.M)[1:]
    rules: dict[str, set[str]] = {}
    for name, body in zip(blocks[::2], blocks[1::2]):
        wildcards = (re.findall(r"^\s+wildcards: (.*)$", body, re.M) or [""])[0]
        trial = wildcards.split("trial=")[1].split(",")[0] if "trial=" in wildcards else None
        rules.setdefault(name, set()).update([trial] if trial else [])
    return rules


@pytest.mark.parametrize(
    "section, key, value, expected",
    [
        # a stride setting: the stride tables and what reads them, never IK
        ("strides", "iqr_whisker", 2.0, {"strides", "strides_summary", "impedance_fit", "transparency"}),
        # a gait-event setting: events (and their load-cell sibling in the one job of a device trial), then strides
        (
            "events",
            "threshold_on_n",
            60.0,
            {"events", "events_loadcell", "strides", "strides_summary", "impedance_fit", "transparency"},
        ),
        # a setting of the subjects' fits only (the validation study does not use it)
        ("impedance", "min_vaf_pct", 1.0, {"impedance_fit"}),
        # a setting of the segment table only: never the generic or scaled model, nor IK after them
        ("model", "brace_attachment_fraction", 0.75, {"model_segments", "impedance_fit"}),
    ],
)
def test_a_changed_setting_reruns_only_what_depends_on_it(finished_run, tmp_path, section, key, value, expected):
    overlay = tmp_path / "overlay.yaml"
    overlay.write_text(yaml.safe_dump({section: {key: value}}))
    rules = _dry_run_rules(finished_run, "--configfile", "config/config.yaml", str(overlay))
    aggregates = {
        "impedance_table",
        "impedance_summary",
        "impedance_figures",
        "impedance_figure",
        "tables_markdown",
        "planning",
        "front_page",
        "all",
    }
    assert set(rules) - aggregates == expected, rules
    assert not {"markers", "ik", "model_scaled", "synthetic_lab", "validation_chunk"} & set(rules)


def test_touching_one_raw_file_reruns_only_what_depends_on_it(finished_run):
    """Last in this file: it changes a raw file's time (and restores it)."""
    import os
    import re

    raw = finished_run / "data/raw/S01/pert050-1.c3d"
    before = raw.stat()
    os.utime(raw, (before.st_atime, before.st_mtime + 3600))
    try:
        res = _snakemake(finished_run, "-n")
    finally:
        os.utime(raw, (before.st_atime, before.st_mtime))
    assert res.returncode == 0, res.stderr[-3000:]
    blocks = re.split(r"^\s*(?:local)?rule (\w+):$", res.stdout, flags=re.M)[1:]
    jobs = [
        (name, (re.findall(r"^\s+wildcards: (.*)$", body, re.M) or [""])[0])
        for name, body in zip(blocks[::2], blocks[1::2])
    ]
    rules = {name for name, _ in jobs}
    assert rules == {
        "markers",
        "ik",
        "events_loadcell",
        "strides",
        "strides_summary",
        "impedance_fit",
        "impedance_table",
        "impedance_summary",
        "impedance_figures",
        "impedance_figure",
        "tables_markdown",
        "planning",
        "front_page",
        "all",
    }, rules
    trials = {w.split("trial=")[1].split(",")[0] for _, w in jobs if "trial=" in w}
    assert trials == {"pert050-1"}
