"""The front page of the report (loper_analysis.report.front_page, the file step, and the report in a real browser).

The headline tables it shows are tested in test_headline.py.
"""

from __future__ import annotations

import base64
import math
import re
import shutil
import subprocess
import sys
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.across_subjects import impedance_summary
from loper_analysis.impedance.identification.group_mean import random_effects_mean
from loper_analysis.report.front_page import RunSettings, front_page_html
from loper_analysis.report.front_page_settings import FrontPageSettings
from loper_analysis.report.headline import (
    device_comparison,
    impedance_summary_ci,
    transparency_verdict,
    truth_recovery,
    validation_verdict,
)
from loper_analysis.stages import study_paths
from tests.browser import report_screen
from tests.headline_tables import device_summary, impedance_row, impedance_table, validation_summary

PATHS = study_paths()

ROOT = Path(__file__).resolve().parents[2]

SETTINGS = dict(
    seed=2024,
    perturbation_onsets_ms=[50, 175, 300],
    perturbation_repeats=2,
    perturbed_side="left",
    filter_cutoff_hz=40.0,
    filter_order=4,
    window_before_s=0.025,
    window_after_s=0.25,
    stiffness_bounds_nm_per_rad=[0.0, 200.0],
    damping_bounds_nms_per_rad=[0.0, 10.0],
    n_starts=10,
    noise_model="null_pairs",
    null_pair_components=6,
    synthetic_variability="study",
    synthetic_walking_duration_s=45.0,
    pulse_force_n=40.0,
    pulse_duration_s=0.1,
)
VERSIONS = {"Python": "3.11.7", "loper_analysis": "0.1.0", "OpenSim": "4.6"}


class _Numbers(HTMLParser):
    """Every ``<span data-q data-v>`` of a fragment: key -> (value, text shown)."""

    def __init__(self):
        super().__init__()
        self.found: dict[str, tuple[float, str]] = {}
        self._open: list[tuple[str, float] | None] = []
        self._text = ""

    def handle_starttag(self, tag, attrs):
        if tag == "span":
            a = dict(attrs)
            self._open.append((a["data-q"], float(a["data-v"])) if "data-q" in a else None)
            self._text = ""

    def handle_data(self, data):
        self._text += data

    def handle_endtag(self, tag):
        if tag == "span" and self._open:
            top = self._open.pop()
            if top is not None:
                assert top[0] not in self.found, top[0]
                self.found[top[0]] = (top[1], self._text)


def _shown(text: str) -> float:
    return math.nan if text == "–" else float(text.replace("\u2212", "-"))


def _decimals_shown(text: str) -> int:
    return len(text.split(".")[1]) if "." in text else 0


def test_fragment_numbers_are_the_tables_numbers():
    """Round trip: every number on the page carries the table's value, and its text rounds that value."""
    table = impedance_table()
    summary = impedance_summary(table)
    ci = impedance_summary_ci(summary)
    truth = truth_recovery(table)
    rmsd = pd.DataFrame(
        {
            "subject": ["S1", "all"],
            "phase": "swing",
            "joint": "knee",
            "rmsd_rad": [0.0958, 0.0679],
            "isv_ave_rad": [0.1338, 0.1338],
            "transparent": [True, True],
            "study_rmsd_rad": 0.071,
            "study_isv_ave_rad": 0.129,
        }
    )
    tr, dev = transparency_verdict(rmsd), device_comparison(device_summary())
    val = validation_verdict(validation_summary())
    page = front_page_html(
        {"S1": "synthetic", "S2": "synthetic", "R1": "recorded"},
        {"S1": ["a", "b"], "S2": ["a", "b"], "R1": ["a"]},
        RunSettings(**SETTINGS),
        VERSIONS,
        device=dev,
        validation=val,
        summary=ci,
        truth=truth,
        figure_png=b"\x89PNG fake",
        transparency=tr,
    )
    parser = _Numbers()
    parser.feed(page)
    found = parser.found
    expected = {}
    for r in ci.to_dict("records"):
        for col in (
            "K_mean_nm_per_rad",
            "K_ci95_low_nm_per_rad",
            "K_ci95_high_nm_per_rad",
            "D_mean_nms_per_rad",
            "D_ci95_low_nms_per_rad",
            "D_ci95_high_nms_per_rad",
            "vaf_pct_mean",
            "n_subjects",
        ):
            expected[f"impedance-summary|{r['joint']}|{r['onset_ms']}|{col}"] = r[col]
    for r in truth.to_dict("records"):
        for p in ("K", "D"):
            for col in truth.columns:
                if col == "n_fits" or col.startswith(f"{p}_"):
                    expected[f"truth-recovery|{p}_{r['joint']}|{col}"] = r[col]
    for r in dev.to_dict("records"):
        for col in ("value", "study_value", "difference_pct"):
            expected[f"device|{r['metric']}|{col}"] = r[col]
    expected["transparency|swing|knee|rmsd_rad"] = 0.0679
    assert set(expected) <= set(found), sorted(set(expected) - set(found))
    for key, value in expected.items():
        shown_value, text = found[key]
        if math.isnan(value):
            assert math.isnan(shown_value) and text == "–", key
            continue
        assert shown_value == value, key  # the full-precision value is the table's
        assert abs(_shown(text) - value) <= 0.5 * 10 ** -_decimals_shown(text) + 1e-12, (key, text, value)
    # the means of the library's summary: hip at 50 ms over S1, S2 and R1
    hip = table[(table.joint == "hip") & (table.onset_ms == 50) & (table.status == "ok")]
    group = random_effects_mean(hip.K_nm_per_rad.to_numpy(float), hip.K_se_nm_per_rad.to_numpy(float))
    assert found["impedance-summary|hip|50|K_mean_nm_per_rad"][0] == group.mean  # 50, 70, 45 weighted
    assert found["impedance-summary|hip|50|n_subjects"][0] == 3
    assert found["truth-recovery|K_hip|K_error_mean_nm_per_rad"] == (6.5, "6.50")
    assert found["truth-recovery|K_hip|K_n_within_tolerance"] == (1, "1")
    assert found["truth-recovery|D_hip|n_fits"] == (2, "2")
    assert found["device|bandwidth_hz|value"] == (38.79, "38.8")
    # the verdicts, without a calibration: 4 of 6 intervals hold the truth, not rejected by the target's 90 %
    # (P(X <= 4 | 6, 0.9) = 1 - 6 · 0.9^5 · 0.1 - 0.9^6 = 0.114265): too few to decide
    assert found["verdict|truth|n_truth_in_ci95"] == (4, "4")
    assert found["verdict|truth|p_reject_ci95"][0] == pytest.approx(0.114265, abs=1e-6)
    assert found["verdict|truth|p_reject_ci95"][1] == "0.11"
    assert "no calibration run named (report.calibration)" in page
    assert "<b>Intervals: too few fits to decide</b>: this run " in page
    assert "</span>/6 (67 %), target 90–98 %, not rejected (p = " in page
    assert "<b>Estimates: too few fits to decide</b>: this run K " in page
    assert found["verdict|transparency|n_transparent"] == (1, "1") and "Transparent</b>" in page
    assert found["verdict|device|max_abs_difference_pct"][1] == "3.3"  # overshoot 31.5 against 30.5
    assert found["verdict|validation|K_max_abs_error"] == (0.02, "0.020")
    assert "data:image/png;base64," + base64.b64encode(b"\x89PNG fake").decode() in page
    assert "2 synthetic (S1, S2) + 1 recorded (R1) subjects, 1–2 walking trials per subject" in page
    assert "Python 3.11.7 · loper_analysis 0.1.0 · OpenSim 4.6" in page


def test_nothing_fitted_and_no_impedance_experiment_are_said():
    table = pd.DataFrame(
        [
            impedance_row("S1", 50, j, math.nan, math.nan, (math.nan,) * 2, (math.nan,) * 2, 5.0, 0.1, status="failed")
            for j in JOINTS
        ]
    )
    common = dict(device=device_comparison(device_summary()), validation=validation_verdict(validation_summary()))
    page = front_page_html(
        {"S1": "synthetic"},
        {"S1": ["a"]},
        RunSettings(**SETTINGS),
        VERSIONS,
        summary=impedance_summary_ci(impedance_summary(table)),
        truth=truth_recovery(table),
        impedance_status={"failed": 3},
        **common,
    )
    assert "no joint was fitted (3 failed;" in page and "(1 synthetic subject, 0 joint fits, 3 failed)" in page
    assert 'id="lf-truth-recovery"' not in page  # no table of nothing
    page = front_page_html({"S1": "synthetic"}, {}, RunSettings(**SETTINGS), VERSIONS, **common)
    assert "No perturbation trials in this run" in page and "no walking trials processed" in page


def _write_results(root: Path) -> None:
    """A small results set in the shapes of a default run: 3 synthetic subjects × 3 onsets × 3 joints, with the
    library's summary and figure, the transparency, device and validation tables."""
    from loper_analysis.stages.impedance.step import impedance_figure
    from loper_analysis.stages.impedance.step import impedance_summary as summary_step

    rows = []
    rng = np.random.default_rng(7)
    truth = {"hip": (50.0, 3.0), "knee": (2.0, 0.1), "ankle": (8.0, 0.3)}
    for s in ("S01", "S02", "S03"):
        for onset in (50, 175, 300):
            for joint, (k, d) in truth.items():
                ke, de = k * (1 + 0.1 * rng.standard_normal()), d * (1 + 0.1 * rng.standard_normal())
                rows.append(impedance_row(s, onset, joint, ke, de, (0.8 * ke, 1.2 * ke), (0.8 * de, 1.2 * de), k, d))
    impedance = root / PATHS.impedance.root
    impedance.mkdir(parents=True)
    pd.DataFrame(rows).to_csv(impedance / "impedance.tsv", sep="\t", index=False)
    summary_step(impedance / "impedance.tsv", impedance / "summary.tsv", impedance / "literature.tsv")
    impedance_figure(impedance / "impedance.tsv", impedance / "impedance.png")
    (root / PATHS.transparency.root).mkdir(parents=True)
    pd.DataFrame(
        {
            "subject": ["S01", "all"],
            "phase": "swing",
            "joint": "knee",
            "rmsd_rad": [0.09, 0.07],
            "isv_ave_rad": [0.13, 0.13],
            "transparent": [True, True],
            "study_rmsd_rad": 0.071,
            "study_isv_ave_rad": 0.129,
        }
    ).to_csv(root / PATHS.transparency.rmsd, sep="\t", index=False)
    (root / PATHS.device.root).mkdir(parents=True)
    device_summary().to_csv(root / PATHS.device.summary, sep="\t", index=False)
    (root / PATHS.validation.root).mkdir(parents=True)
    validation_summary().to_csv(root / PATHS.validation.summary, sep="\t", index=False)


def _front_page(root: Path, versions=VERSIONS, calibration: Path | None = None, fingerprint: str = "") -> str:
    from loper_analysis.stages.report.step import FrontPageFiles, front_page

    r = root / "results"
    files = FrontPageFiles(
        validation=r / "validation/summary.tsv",
        device=r / "device/summary.tsv",
        impedance=r / "impedance/impedance.tsv",
        summary=r / "impedance/summary.tsv",
        figure=r / "impedance/impedance.png",
        calibration=calibration,
        rmsd=r / "transparency/rmsd.tsv",
    )
    return front_page(
        files,
        r / "report/front_page.html",
        {s: "synthetic" for s in ("S01", "S02", "S03")},
        {s: ["walk-nodevice", "walk-device", "pert050-1"] for s in ("S01", "S02", "S03")},
        FrontPageSettings(RunSettings(**SETTINGS), None if calibration is None else str(calibration), fingerprint),
        versions=versions,
    )


#: The design fingerprint of the calibration written by :func:`_calibration_file`.
FINGERPRINT = "0123456789abcdef"


def _calibration_file(root: Path, **cells) -> Path:
    """A calibration table of 34 subjects, every joint's K and D: 100 fits, 94 intervals holding the truth, 92
    estimates within tolerance; ``cells``: column -> (row, value) changed."""
    from loper_analysis.report.calibration import CALIBRATION_COLUMNS

    rows = []
    for joint in JOINTS:
        for p, floor in (("K", 2.0), ("D", 0.05)):
            rows.append(
                dict(
                    joint=joint, parameter=p, n_fits=100, n_truth_in_ci95=94, n_within_tolerance=92,
                    n_not_identifiable=20, tolerance_pct=10.0 if p == "K" else 15.0,
                    tolerance_floor_nm_per_rad=floor if p == "K" else "", tolerance_floor_nms_per_rad=floor if p == "D"
                    else "", calibration_date="2026-12-01", seed=2024, n_subjects=34, n_subject_onset_fits=102,
                    mode="coordinates", code_version="loper-analysis 0.1.0, commit abc1234",
                    design_fingerprint=FINGERPRINT,
                )
            )  # fmt: skip
    table = pd.DataFrame(rows, columns=list(CALIBRATION_COLUMNS)).astype(object)
    for column, (row, value) in cells.items():
        table.loc[row, column] = value
    path = root / "truth_recovery.tsv"
    table.to_csv(path, sep="\t", index=False)
    return path


def test_the_file_step_takes_the_verdicts_from_a_calibration_of_this_design(tmp_path):
    """The small results set (27 fits, 51 of 54 intervals holding the truth, K 24 and D 26 within tolerance) against a
    calibration whose 564 of 600 intervals and 276 of 300 K and D within tolerance meet the targets: this run agrees
    with it, green; the calibration's shares beside the run's counts in the truth table."""
    _write_results(tmp_path)
    page = _front_page(tmp_path, calibration=_calibration_file(tmp_path), fingerprint=FINGERPRINT)
    assert (
        "verdict from the calibration run of 2026-12-01, "
        '<span data-q="verdict|calibration|n_subject_onset_fits" data-v="102">102</span> fits '
        '(<span data-q="verdict|calibration|n_subjects" data-v="34">34</span> subjects, seed 2024), design '
        "fingerprint matches this run." in page
    )
    assert "Verdicts on the truth: intervals ✓ when the calibration run's share meets the target" in page  # the rule
    assert "(coordinates level, loper-analysis 0.1.0, commit abc1234, design fingerprint 0123456789abcdef)." in page
    found = _Numbers()
    found.feed(page)
    assert found.found["verdict|calibration|n_truth_in_ci95"] == (564, "564")
    assert found.found["verdict|truth|n_truth_in_ci95"] == (51, "51")
    assert found.found["verdict|truth|K_n_within_tolerance"] == (24, "24")
    assert found.found["calibration|K_hip|within_tolerance_pct"] == (92.0, "92")
    assert found.found["calibration|D_ankle|truth_in_ci95_pct"] == (94.0, "94")
    assert "<b>Intervals hold the truth</b>" in page and "<b>Estimates within tolerance</b>" in page
    assert "calibration<br>within tol." in page
    # the same calibration of another design: the run's own counts, with the fallback's wording
    page = _front_page(tmp_path, calibration=_calibration_file(tmp_path), fingerprint="fedcba9876543210")
    assert "is of another design (fingerprint 0123456789abcdef; this run fedcba9876543210)" in page
    assert "too few to decide" in page and "calibration<br>within tol." not in page


def test_the_file_step_refuses_a_malformed_calibration_naming_file_column_and_value(tmp_path):
    _write_results(tmp_path)
    path = _calibration_file(tmp_path, n_within_tolerance=(4, "ninety"))
    with pytest.raises(LoperInputError) as err:
        _front_page(tmp_path, calibration=path, fingerprint=FINGERPRINT)
    said = "column 'n_within_tolerance', row 5 (ankle K): 'ninety' is not a whole number >= 0"
    assert str(err.value) == f"{path}: {said}"


def test_the_file_step_writes_the_same_bytes_from_the_same_files(tmp_path):
    _write_results(tmp_path)
    first = (_front_page(tmp_path), (tmp_path / PATHS.report.front_page).read_bytes())
    again = _front_page(tmp_path)
    assert first[1] == again.encode() == (tmp_path / PATHS.report.front_page).read_bytes()
    png = (tmp_path / PATHS.impedance.figure).read_bytes()
    embedded = re.search(r'src="data:image/png;base64,([^"]+)"', again).group(1)
    assert base64.b64decode(embedded) == png  # the figure, byte for byte
    assert str(tmp_path) not in again and "impedance.png" not in again  # no path on the page
    summary = pd.read_csv(tmp_path / PATHS.impedance.summary, sep="\t")
    assert f'data-v="{float(summary.K_group_mean_nm_per_rad.iloc[0])!r}"' in again  # hip, 50 ms, from the file
    assert list(summary.joint) == ["hip"] * 3 + ["knee"] * 3 + ["ankle"] * 3 and (summary.n_subjects == 3).all()
    assert not list((tmp_path / PATHS.report.root).glob(".*partial"))  # written through the atomic writer


def test_the_report_shows_the_headline_tables_on_its_first_screen(tmp_path):
    """The workflow's own report text (workflow/report/workflow.rst) in a Snakemake report of a small results set,
    opened in headless Chromium at 1400×900: both headline tables lie wholly within the first screen."""
    screen = report_screen()
    if screen.chromium_path() is None:
        pytest.skip("no Chromium at /usr/bin/chromium (or $CHROMIUM): the first screen cannot be rendered")
    _write_results(tmp_path)
    page = _front_page(tmp_path)
    (tmp_path / "config").mkdir()
    shutil.copy(ROOT / "config/config.yaml", tmp_path / "config/config.yaml")
    (tmp_path / "workflow/report").mkdir(parents=True)
    shutil.copy(ROOT / "workflow/report/workflow.rst", tmp_path / "workflow/report/workflow.rst")
    (tmp_path / "Snakefile").write_text(
        'configfile: "config/config.yaml"\n\n\nreport: "workflow/report/workflow.rst"\n\n\n'
        f'rule all:\n    input:\n        "{PATHS.report.front_page}",\n'
    )
    res = subprocess.run(
        [sys.executable, "-m", "snakemake", "--report", "report.html"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr[-3000:]
    measured = screen.first_screen(tmp_path / "report.html", tmp_path / "first_screen.png")
    assert measured["viewport"] == [1400, 900]
    boxes = measured["boxes"]
    for table in ("lf-impedance-summary", "lf-truth-recovery"):
        box = boxes[table]
        assert 0 <= box["top"] < box["bottom"] <= 900 and 0 <= box["left"] < box["right"] <= 1400, (table, box)
    assert boxes["lf-impedance-summary"]["bottom"] <= boxes["lf-truth-recovery"]["top"]
    assert screen.problems(measured) == []
    # the first screen shows the summary's number for the hip at 50 ms, as the fragment has it
    shown = re.search(r'data-q="impedance-summary\|hip\|50\|K_mean_nm_per_rad" data-v="[^"]+">([^<]+)<', page)
    assert f"hip 50 {shown.group(1)} [" in measured["text"]
    assert (tmp_path / "first_screen.png").read_bytes()[:4] == b"\x89PNG"
    # the methods text follows the results
    assert measured["boxes"]["lf-run"]["bottom"] > 900
