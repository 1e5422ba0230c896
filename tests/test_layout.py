"""The study's files (``loper_analysis.layout``): patterns, wildcards, trials on disk, bundles, targets."""

from __future__ import annotations

import hashlib
from pathlib import Path

import pytest

from loper_analysis.layout import fill
from loper_analysis.stages import RESULT_FILES, STAGES, all_targets, report_tables, study_paths
from loper_analysis.stages.impedance.files import fit_files, fit_inputs
from loper_analysis.stages.planning.files import planning_files
from tests.study_files import CONFIG, study_on, touch
from tests.workflow_copy import copy_workflow, snakemake

ROOT = Path(__file__).resolve().parents[1]


def test_patterns_are_the_folders_and_names_of_the_docs():
    paths = study_paths("lab/raw")
    assert paths.ik.angles == "results/ik/{subject}/{trial}.angles.tsv"
    assert paths.impedance.fit == "results/impedance/{subject}/{onset}.tsv"
    assert paths.raw.c3d == "lab/raw/{subject}/{trial}.c3d"
    assert paths.log("ik", "{subject}/{trial}") == "results/logs/ik/{subject}/{trial}.log"
    assert paths.benchmark("planning", "plan") == "results/benchmarks/planning/plan.tsv"
    # every stage folder holds its own files only
    assert all(getattr(paths, stage).root == f"results/{stage}" for stage in RESULT_FILES)


def test_an_unknown_file_or_folder_is_named():
    with pytest.raises(AttributeError, match=r"results/ik: no file 'angle' \(files: mot, chunk, angles"):
        _ = study_paths().ik.angle
    with pytest.raises(AttributeError, match="no results folder 'kinematics'"):
        _ = study_paths().kinematics


def test_fill_leaves_the_wildcards_not_given():
    assert fill(study_paths().ik.angles, trial="static") == "results/ik/{subject}/static.angles.tsv"
    assert fill(study_paths().impedance.fit, subject="S01", onset=50) == "results/impedance/S01/050.tsv"
    assert fill(study_paths().impedance.fit, subject="S01", onset="175") == "results/impedance/S01/175.tsv"


def test_a_recorded_subjects_trials_are_those_on_disk(tmp_path):
    raw = tmp_path / "raw" / "R01"
    for t in ("static", "walk-nodevice", "pert050-1"):
        touch(raw / f"{t}.c3d")
    study = study_on(
        tmp_path, {"R01": {"source": "recorded"}, "S01": {"source": "synthetic"}}, device={"subject": None}
    )
    assert study.subject_trials("R01") == ["walk-nodevice", "pert050-1"]
    assert len(study.subject_trials("S01")) == 8  # every walking trial of the design
    assert study.processed_subjects() == ["R01", "S01"]
    assert study.transparency_subjects() == ["S01"]
    targets = all_targets(study)
    # plates in pert050-1 only: its external loads and force-plate figure, one note for the other trial
    assert "results/grf/R01/pert050-1.grf.mot" in targets and "results/grf/R01/walk-nodevice.grf.mot" not in targets
    assert study.said == [
        f"note: {raw / 'walk-nodevice.c3d'}: no force platforms (FORCE_PLATFORM:USED 0 or absent): events from "
        f"the belt channels (events.grf_channels: {CONFIG['events']['grf_channels']}), no OpenSim external "
        "loads (results/grf/R01/walk-nodevice.grf.mot) for this trial"
    ]
    assert "results/validation/summary.tsv" in targets and "results/device/summary.tsv" not in targets
    # nor does the Markdown of the run's tables ask for it (the default run would build the device tests then)
    assert "Device" not in report_tables(study) and "results/device/summary.tsv" not in set(
        report_tables(study).values()
    )


def test_a_fits_files_are_its_onsets_own_trials_and_the_null_pairs(tmp_path):
    raw = tmp_path / "raw" / "R01"
    for t in ("static", "walk-device", "pert050-1", "pert175-1"):
        touch(raw / f"{t}.c3d")
    study = study_on(tmp_path, {"R01": {"source": "recorded"}})
    fits = fit_files(study, "R01")
    assert list(fits) == [50, 175, 300]
    assert list(fits[50].trials) == ["pert050-1"] and fits[50].trials["pert050-1"].force == (
        "results/events/R01/pert050-1.force.tsv"
    )
    assert list(fits[50].null_trials) == ["walk-device", "pert050-1", "pert175-1"]
    assert fits[300].trials == {} and fits[300].null_trials == {}  # a missing onset reads nothing
    assert fits[175].outputs.curves == "results/impedance/R01/175.curves.tsv" and fits[175].truth is None
    inputs = fit_inputs(study, "R01")
    assert len(inputs) == len(set(inputs)) and "results/markers/R01/pert175-1.trc" in inputs
    assert planning_files(study, "R01").impedance == tuple(
        f"results/impedance/R01/{o}.tsv" for o in ("050", "175", "300")
    )


def test_checksums_only_of_a_recorded_subjects_raw_files(tmp_path):
    c3d = touch(tmp_path / "raw" / "R01" / "static.c3d", b"abc")
    touch(tmp_path / "raw" / "S01" / "static.c3d", b"abc")
    study = study_on(tmp_path, {"R01": {"source": "recorded"}, "S01": {"source": "synthetic"}})
    paths = [str(c3d), str(tmp_path / "raw" / "S01" / "static.c3d"), "results/markers/R01/static.trc"]
    assert study.recorded_checksums(paths) == {str(c3d): hashlib.sha256(b"abc").hexdigest()}


def test_the_workflow_reads_and_writes_raw_files_in_the_configs_raw_dir(tmp_path):
    work = copy_workflow(tmp_path)
    run = snakemake(work, "-n", "--config", "raw_dir=lab/raw")
    assert run.returncode == 0, run.stderr[-2000:]
    written = {line.split(": ", 1)[1] for line in run.stdout.splitlines() if line.startswith("    output: ")}
    assert "lab/raw/S01/truth.yaml" in written
    assert not [p for line in written for p in line.split(", ") if p.startswith("data/raw")]


def test_ik_reads_the_static_trials_markers_of_a_subject_with_a_static_trial(tmp_path):
    for subject in ("R01", "R02"):
        touch(tmp_path / "raw" / subject / "walk-nodevice.c3d")
    touch(tmp_path / "raw" / "R01" / "static.c3d")
    rows = {
        "R01": {"source": "recorded"},
        "R02": {"source": "recorded", "model_osim": "lab/R02.osim"},  # a model, no static trial
        "S01": {"source": "synthetic"},
    }
    study = study_on(tmp_path, rows)
    assert study.static_markers("R01") == ["results/markers/R01/static.trc"]
    assert study.static_markers("S01") == ["results/markers/S01/static.trc"]  # generated with its walks
    assert study.static_markers("R02") == []  # IK compares with the model's markers


def test_the_workflow_compiles_the_packages_bytecode_when_it_starts(tmp_path):
    """The README's set-up runs no `compileall`: the Snakefile compiles the package once, before any job (each job
    would compile it again otherwise). A module's bytecode removed comes back with a dry run."""
    import importlib.util

    import loper_analysis.gait.events as module

    cached = Path(importlib.util.cache_from_source(module.__file__))
    cached.unlink(missing_ok=True)
    copy_workflow(tmp_path)
    res = snakemake(tmp_path, "-n", "-q")
    assert res.returncode == 0, res.stderr[-2000:]
    assert cached.is_file() and cached.stat().st_mtime >= Path(module.__file__).stat().st_mtime


def test_the_report_tables_are_each_stages_own_tables_in_the_stages_order(tmp_path):
    """The Markdown rendering's tables come from the stages that own them, in the workflow's order, each a file of
    its own stage's folder."""
    study = study_on(tmp_path, {"S01": {"source": "synthetic"}})
    tables = report_tables(study)
    assert list(tables) == [
        "Strides per trial",
        "Inverse dynamics per trial",
        "Transparency: RMSD vs ISV_ave",
        "Transparency: interaction force",
        "Device",
        "Impedance per subject, onset and joint",
        "Across-subject summary",
        "Literature",
        "Validation study",
    ]
    for stage in STAGES:
        for path in (stage.tables(study) if stage.tables else {}).values():
            assert path.startswith(f"results/{stage.name}/"), (stage.name, path)
