"""The front page's truth verdicts through the workflow: the rule ``front_page`` takes the calibration table named by
``report.calibration`` as an input, and the page says whether it calibrates this run's design.

A short study on a copy of the workflow (one synthetic subject, 60 s trials, one onset, no device tests, a small
validation study), with a calibration table written for its design (its fingerprint as the report's settings
compute it from the same config), then one of another design: only the front page reruns.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest
import yaml

from loper_analysis.constants import JOINTS
from loper_analysis.report.calibration import CALIBRATION_COLUMNS
from loper_analysis.stages import study_paths
from loper_analysis.stages.settings import stage_settings
from tests.workflow_copy import copy_workflow, snakemake

pytestmark = pytest.mark.slow  # Snakemake runs on whole trials

PATHS = study_paths()


def _short_study(work: Path) -> dict:
    """The shipped config, made short: one synthetic subject, one 60 s trial at 50 ms (enough perturbed strides for
    a fit), no device tests."""
    config = yaml.safe_load((work / "config/config.yaml").read_text())
    (work / "config/subjects.tsv").write_text(
        "subject\tsource\tsex\tage_yr\theight_m\tmass_kg\nS01\tsynthetic\tmale\t26\t1.80\t72.0\n"
    )
    config["synthetic"]["walking_duration_s"] = 60.0
    config["study"].update(perturbation_onsets_ms=[50], perturbation_repeats=1)
    config["impedance"]["n_starts"] = 3
    config["validation"].update(stiffness_levels_nm_per_rad=[0.0, 150.0], damping_levels_nms_per_rad=[0.0, 4.0])
    config["device"]["subject"] = None
    (work / "config/config.yaml").write_text(yaml.safe_dump(config, sort_keys=False))
    return config


def _write_calibration(path: Path, fingerprint: str, date: str) -> None:
    """A calibration of 34 subjects: per joint, K and D, 100 fits, 94 intervals holding the truth, 92 within
    tolerance."""
    rows = [
        {
            "joint": joint, "parameter": p, "n_fits": 100, "n_truth_in_ci95": 94, "n_within_tolerance": 92,
            "n_not_identifiable": 20, "tolerance_pct": 10.0 if p == "K" else 15.0,
            "tolerance_floor_nm_per_rad": 2.0 if p == "K" else None,
            "tolerance_floor_nms_per_rad": 0.05 if p == "D" else None, "calibration_date": date, "seed": 2024,
            "n_subjects": 34, "n_subject_onset_fits": 102, "mode": "coordinates",
            "code_version": "loper-analysis 0.1.0", "design_fingerprint": fingerprint,
        }
        for joint in JOINTS
        for p in ("K", "D")
    ]  # fmt: skip
    pd.DataFrame(rows, columns=list(CALIBRATION_COLUMNS)).to_csv(path, sep="\t", index=False)


def test_the_front_page_takes_its_truth_verdicts_from_the_named_calibration(tmp_path):
    work = copy_workflow(tmp_path)
    config = _short_study(work)
    report = stage_settings(config, "report")
    assert report.calibration == "config/calibration/truth_recovery.tsv"
    calibration = work / report.calibration
    _write_calibration(calibration, report.design_fingerprint, "2026-12-01")
    res = snakemake(work, PATHS.report.front_page, timeout=900)
    assert res.returncode == 0, res.stderr[-3000:]
    page = (work / PATHS.report.front_page).read_text()
    assert "verdict from the calibration run of 2026-12-01, " in page
    assert "design fingerprint matches this run." in page and f"design fingerprint {report.design_fingerprint})" in page
    assert "<b>Recovering the truth</b> (1 synthetic subject, " in page and "calibration<br>within tol." in page

    # a calibration of another design: the rule reruns for its input alone, and the page says so
    _write_calibration(calibration, "0123456789abcdef", "2026-12-02")
    dry = snakemake(work, PATHS.report.front_page, "-n", timeout=300)
    assert dry.returncode == 0 and "rule front_page:" in dry.stdout and "rule impedance_fit:" not in dry.stdout
    res = snakemake(work, PATHS.report.front_page, timeout=300)
    assert res.returncode == 0, res.stderr[-3000:]
    page = (work / PATHS.report.front_page).read_text()
    assert (
        "the calibration run of 2026-12-02 (102 fits) is of another design (fingerprint 0123456789abcdef; this run "
        f"{report.design_fingerprint}): this run's own counts, too few to decide" in page
    )
