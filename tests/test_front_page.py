"""The front page of the report (loper_analysis.front_page, the file step, and the report in a real browser)."""

from __future__ import annotations

import base64
import importlib.util
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
from loper_analysis.front_page import (
    RunSettings,
    ci_coverage_p,
    device_comparison,
    front_page_html,
    impedance_summary_ci,
    transparency_verdict,
    truth_recovery,
    validation_verdict,
)
from loper_analysis.impedance import IMPEDANCE_COLUMNS, impedance_summary
from loper_analysis.reference import STUDY_DEVICE

ROOT = Path(__file__).resolve().parents[1]

SETTINGS = dict(
    seed=2024, perturbation_onsets_ms=[50, 175, 300], perturbation_repeats=2, perturbed_side="left",
    filter_cutoff_hz=40.0, filter_order=4, window_before_s=0.025, window_after_s=0.25,
    stiffness_bounds_nm_per_rad=[0.0, 200.0], damping_bounds_nms_per_rad=[0.0, 10.0], n_starts=10,
    noise_model="null_pairs", null_pair_components=6, synthetic_variability="study",
    synthetic_walking_duration_s=45.0, pulse_force_n=40.0, pulse_duration_s=0.1,
)
VERSIONS = {"Python": "3.11.7", "loper_analysis": "0.1.0", "OpenSim": "4.6"}
#: t(0.975, 2): the 95 % quantile factor of a mean over 3 subjects
T_975_2 = 4.302652729749464


def _row(subject, onset, joint, k, d, k_ci, d_ci, k_true=None, d_true=None, status="ok") -> dict:
    row = dict.fromkeys(IMPEDANCE_COLUMNS)
    row.update(subject=subject, onset_ms=onset, joint=joint, K_nm_per_rad=k, D_nms_per_rad=d,
               K_ci95_low_nm_per_rad=k_ci[0], K_ci95_high_nm_per_rad=k_ci[1], D_ci95_low_nms_per_rad=d_ci[0],
               D_ci95_high_nms_per_rad=d_ci[1], vaf_pct=90.0, n_strides=10, status=status, reason="")
    if k_true is not None:
        row.update(K_true_nm_per_rad=k_true, D_true_nms_per_rad=d_true, K_error_nm_per_rad=k - k_true,
                   D_error_nms_per_rad=d - d_true)
    return row


def _impedance() -> pd.DataFrame:
    """Two synthetic subjects (one failed fit) and a recorded one, with known errors."""
    nan = math.nan
    return pd.DataFrame([
        # hip K: error -2 (within 10 % of 52, truth in CI); 15 (outside both). D: -0.6 (outside both); -0.2 (in both)
        _row("S1", 50, "hip", 50.0, 3.0, (40.0, 60.0), (2.5, 3.5), 52.0, 3.6),
        _row("S2", 50, "hip", 70.0, 4.0, (60.0, 80.0), (3.0, 5.0), 55.0, 4.2),
        _row("S1", 175, "hip", nan, nan, (nan, nan), (nan, nan), 40.0, 2.0, status="failed"),
        # knee K: error -2 = the 2 N·m/rad floor of the tolerance (within); D: -0.02 (within)
        _row("S1", 50, "knee", 1.0, 0.10, (0.0, 4.0), (0.0, 0.3), 3.0, 0.12, status="not_identifiable"),
        _row("R1", 50, "hip", 45.0, 3.3, (30.0, 60.0), (2.0, 4.6)),  # recorded: no truth
    ])


def test_ci_of_the_across_subject_mean_is_students_t():
    summary = pd.DataFrame({"joint": ["hip", "knee"], "onset_ms": [50, 50], "n_subjects": [3, 1],
                            "n_not_identifiable": [1, 0], "K_mean_nm_per_rad": [10.0, 5.0],
                            "K_sd_nm_per_rad": [2.0, np.nan], "D_mean_nms_per_rad": [0.3, 0.1],
                            "D_sd_nms_per_rad": [0.06, np.nan], "vaf_pct_mean": [95.0, 80.0]})
    ci = impedance_summary_ci(summary, "s.tsv")
    half_k = T_975_2 * 2.0 / math.sqrt(3)  # 4.968 N·m/rad
    assert ci.loc[0, "K_ci95_low_nm_per_rad"] == pytest.approx(10.0 - half_k, rel=1e-12)
    assert ci.loc[0, "K_ci95_high_nm_per_rad"] == pytest.approx(14.968275, abs=1e-6)
    assert ci.loc[0, "D_ci95_high_nms_per_rad"] == pytest.approx(0.3 + T_975_2 * 0.06 / math.sqrt(3), rel=1e-12)
    assert math.isnan(ci.loc[1, "K_ci95_low_nm_per_rad"])  # one subject: no interval
    assert ci.loc[1, "K_mean_nm_per_rad"] == 5.0 and ci.loc[0, "n_not_identifiable"] == 1


def test_truth_recovery_counts_the_known_errors():
    truth = truth_recovery(_impedance(), "i.tsv").set_index("joint")
    assert list(truth.index) == ["hip", "knee"]  # the recorded subject has no truth, no ankle rows
    hip = truth.loc["hip"]
    assert (hip.n_subjects, hip.n_fits, hip.n_failed) == (2, 2, 1)
    assert hip.K_error_mean_nm_per_rad == pytest.approx(6.5)  # (-2 + 15) / 2
    assert hip.K_error_median_abs_nm_per_rad == pytest.approx(8.5)
    assert hip.K_error_median_abs_pct == pytest.approx((2 / 52 + 15 / 55) / 2 * 100)  # 15.56 %
    assert (hip.K_n_within_tolerance, hip.K_n_truth_in_ci95) == (1, 1)
    assert hip.D_error_mean_nms_per_rad == pytest.approx(-0.4)
    assert (hip.D_n_within_tolerance, hip.D_n_truth_in_ci95) == (1, 1)
    knee = truth.loc["knee"]
    assert (knee.n_fits, knee.K_n_within_tolerance, knee.K_n_truth_in_ci95, knee.D_n_within_tolerance) == (1, 1, 1, 1)
    # 4 of 6 intervals hold the truth: P(X <= 4 | n = 6, 0.95) = 1 - 6 * 0.95**5 * 0.05 - 0.95**6
    assert ci_coverage_p(4, 6) == pytest.approx(1 - 6 * 0.95**5 * 0.05 - 0.95**6, rel=1e-12)
    assert ci_coverage_p(4, 6) == pytest.approx(0.032774, abs=1e-6)


def test_transparency_device_and_validation_verdicts():
    rmsd = pd.DataFrame({
        "subject": ["S1", "S2", "all", "S1", "S2", "all"], "phase": ["stance"] * 3 + ["swing"] * 3,
        "joint": ["hip"] * 6, "rmsd_rad": [0.02, 0.03, 0.025, 0.07, np.nan, 0.07],
        "isv_ave_rad": [0.04, 0.04, 0.04, 0.06, np.nan, 0.06],
        "transparent": [True, True, True, False, np.nan, False], "study_rmsd_rad": 0.024, "study_isv_ave_rad": 0.04})
    tr = transparency_verdict(rmsd, "r.tsv")
    assert tr.transparent.tolist() == [True, False]
    assert tr.n_subjects.tolist() == [2, 1] and tr.n_subjects_transparent.tolist() == [2, 0]
    device = pd.DataFrame({"metric": ["bandwidth_hz", "rise_time_ms", "overshoot_pct", "steady_state_40n_n",
                                      "rise_time_ms_at_20n"], "value": [42.9, 10.0, 30.5, 36.0, 9.7]})
    dev = device_comparison(device, "d.tsv").set_index("metric")
    assert list(dev.index) == list(STUDY_DEVICE)
    assert dev.loc["bandwidth_hz", "difference_pct"] == pytest.approx(10.0)  # 42.9 Hz against the study's 39
    assert dev.loc["rise_time_ms", "study_value"] == 10.0
    val = validation_verdict(_validation(), "v.tsv").set_index("parameter")
    assert val.loc["K", "max_error"] == 0.02 and val.loc["D", "min_error"] == -0.001
    assert val.within_study.all() and val.loc["K", "n_combinations"] == 729


def _validation() -> pd.DataFrame:
    return pd.DataFrame({"condition": ["no_noise", "no_noise", "noise"], "parameter": ["K_hip", "D_hip", "K_hip"],
                         "min_error": [-0.01, -0.001, -70.0], "max_error": [0.02, 0.002, 40.0], "n": 729,
                         "study_min_error": [-0.87, -0.092, -6.2], "study_max_error": [0.59, 0.047, 6.5]})


def _device() -> pd.DataFrame:
    return pd.DataFrame({"metric": list(STUDY_DEVICE), "value": [38.79, 9.9, 31.5, 35.3]})


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
    table = _impedance()
    summary = impedance_summary(table)
    ci = impedance_summary_ci(summary)
    truth = truth_recovery(table)
    rmsd = pd.DataFrame({"subject": ["S1", "all"], "phase": "swing", "joint": "knee", "rmsd_rad": [0.0958, 0.0679],
                         "isv_ave_rad": [0.1338, 0.1338], "transparent": [True, True], "study_rmsd_rad": 0.071,
                         "study_isv_ave_rad": 0.129})
    tr, dev, val = transparency_verdict(rmsd), device_comparison(_device()), validation_verdict(_validation())
    page = front_page_html({"S1": "synthetic", "S2": "synthetic", "R1": "recorded"},
                           {"S1": ["a", "b"], "S2": ["a", "b"], "R1": ["a"]}, RunSettings(**SETTINGS), VERSIONS,
                           device=dev, validation=val, summary=ci, truth=truth, figure_png=b"\x89PNG fake",
                           transparency=tr)
    parser = _Numbers()
    parser.feed(page)
    found = parser.found
    expected = {}
    for r in ci.to_dict("records"):
        for col in ("K_mean_nm_per_rad", "K_ci95_low_nm_per_rad", "K_ci95_high_nm_per_rad", "D_mean_nms_per_rad",
                    "D_ci95_low_nms_per_rad", "D_ci95_high_nms_per_rad", "vaf_pct_mean", "n_subjects"):
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
    assert found["impedance-summary|hip|50|K_mean_nm_per_rad"] == (55.0, "55.0")  # (50 + 70 + 45) / 3
    assert found["impedance-summary|hip|50|n_subjects"][0] == 3
    assert found["truth-recovery|K_hip|K_error_mean_nm_per_rad"] == (6.5, "6.50")
    assert found["truth-recovery|K_hip|K_n_within_tolerance"] == (1, "1")
    assert found["truth-recovery|D_hip|n_fits"] == (2, "2")
    assert found["device|bandwidth_hz|value"] == (38.79, "38.8")
    # the verdicts: 4 of 6 intervals hold the truth, too few for 95 % (p = 0.033)
    assert found["verdict|truth|n_truth_in_ci95"] == (4, "4")
    assert "Truth missed" in page and "binomial p = 0.03" in page
    assert found["verdict|transparency|n_transparent"] == (1, "1") and "Transparent</b>" in page
    assert found["verdict|device|max_abs_difference_pct"][1] == "3.3"  # overshoot 31.5 against 30.5
    assert found["verdict|validation|K_max_abs_error"] == (0.02, "0.020")
    assert "data:image/png;base64," + base64.b64encode(b"\x89PNG fake").decode() in page
    assert "2 synthetic (S1, S2) + 1 recorded (R1) subjects, 1–2 walking trials per subject" in page
    assert "Python 3.11.7 · loper_analysis 0.1.0 · OpenSim 4.6" in page


def test_nothing_fitted_and_no_impedance_experiment_are_said():
    table = pd.DataFrame([_row("S1", 50, j, math.nan, math.nan, (math.nan,) * 2, (math.nan,) * 2, 5.0, 0.1,
                               status="failed") for j in JOINTS])
    common = dict(device=device_comparison(_device()), validation=validation_verdict(_validation()))
    page = front_page_html({"S1": "synthetic"}, {"S1": ["a"]}, RunSettings(**SETTINGS), VERSIONS,
                           summary=impedance_summary_ci(impedance_summary(table)), truth=truth_recovery(table),
                           impedance_status={"failed": 3}, **common)
    assert "no joint was fitted (3 failed;" in page and "(1 synthetic subject, 0 joint fits, 3 failed)" in page
    assert 'id="lf-truth-recovery"' not in page  # no table of nothing
    page = front_page_html({"S1": "synthetic"}, {}, RunSettings(**SETTINGS), VERSIONS, **common)
    assert "No perturbation trials in this run" in page and "no walking trials processed" in page


@pytest.mark.parametrize(("call", "message"), [
    (lambda: impedance_summary_ci(pd.DataFrame({"joint": ["hip"]}), "s.tsv"),
     "s.tsv: impedance summary: column(s) ['onset_ms', 'n_subjects'"),
    (lambda: impedance_summary_ci(pd.DataFrame({
        "joint": ["hip"], "onset_ms": [50], "n_subjects": [0], "n_not_identifiable": [0], "K_mean_nm_per_rad": [1.0],
        "K_sd_nm_per_rad": [1.0], "D_mean_nms_per_rad": [1.0], "D_sd_nms_per_rad": [1.0], "vaf_pct_mean": [90.0]}),
        "s.tsv"), "s.tsv: row 0 (hip 50 ms): n_subjects must be an integer >= 1, got 0"),
    (lambda: transparency_verdict(pd.DataFrame({
        "subject": ["all"], "phase": ["swing"], "joint": ["hip"], "rmsd_rad": [0.1], "isv_ave_rad": [0.2],
        "transparent": ["maybe"], "study_rmsd_rad": [0.1], "study_isv_ave_rad": [0.1]}), "r.tsv"),
     "r.tsv: row 0: column 'transparent' must be True, False or blank, got 'maybe'"),
    (lambda: device_comparison(pd.DataFrame({"metric": ["bandwidth_hz"], "value": [39.0]}), "d.tsv"),
     "d.tsv: device summary: metric 'rise_time_ms' missing"),
    (lambda: device_comparison(pd.DataFrame({"metric": list(STUDY_DEVICE), "value": ["x", 1, 1, 1]}), "d.tsv"),
     "d.tsv: value of metric 'bandwidth_hz' must be a number, got 'x'"),
    (lambda: truth_recovery(_impedance().assign(K_ci95_low_nm_per_rad="?"), "i.tsv"),
     "i.tsv: fitted rows: column 'K_ci95_low_nm_per_rad', row 0 must be a number, got '?'"),
])
def test_bad_tables_are_refused_naming_file_field_and_value(call, message):
    with pytest.raises(LoperInputError) as err:
        call()
    assert message in str(err.value)


def _write_results(root: Path) -> None:
    """A small results set in the shapes of a default run: 3 synthetic subjects × 3 onsets × 3 joints, with the
    library's summary and figure, the transparency, device and validation tables."""
    from loper_analysis.steps.impedance import impedance_figure
    from loper_analysis.steps.impedance import impedance_summary as summary_step

    rows = []
    rng = np.random.default_rng(7)
    truth = {"hip": (50.0, 3.0), "knee": (2.0, 0.1), "ankle": (8.0, 0.3)}
    for s in ("S01", "S02", "S03"):
        for onset in (50, 175, 300):
            for joint, (k, d) in truth.items():
                ke, de = k * (1 + 0.1 * rng.standard_normal()), d * (1 + 0.1 * rng.standard_normal())
                rows.append(_row(s, onset, joint, ke, de, (0.8 * ke, 1.2 * ke), (0.8 * de, 1.2 * de), k, d))
    tables = root / "results/tables"
    tables.mkdir(parents=True)
    pd.DataFrame(rows).to_csv(tables / "impedance.tsv", sep="\t", index=False)
    summary_step(tables / "impedance.tsv", tables / "impedance_summary.tsv", tables / "literature.tsv")
    impedance_figure(tables / "impedance.tsv", root / "results/figures/impedance.png")
    (root / "results/transparency").mkdir(parents=True)
    pd.DataFrame({"subject": ["S01", "all"], "phase": "swing", "joint": "knee", "rmsd_rad": [0.09, 0.07],
                  "isv_ave_rad": [0.13, 0.13], "transparent": [True, True], "study_rmsd_rad": 0.071,
                  "study_isv_ave_rad": 0.129}).to_csv(root / "results/transparency/rmsd.tsv", sep="\t", index=False)
    (root / "results/device").mkdir(parents=True)
    _device().to_csv(root / "results/device/summary.tsv", sep="\t", index=False)
    (root / "results/validation").mkdir(parents=True)
    _validation().to_csv(root / "results/validation/summary.tsv", sep="\t", index=False)


def _front_page(root: Path, versions=VERSIONS) -> str:
    from loper_analysis.steps.report import front_page

    r = root / "results"
    return front_page(r / "report/front_page.html", r / "device/summary.tsv", r / "validation/summary.tsv",
                      {s: "synthetic" for s in ("S01", "S02", "S03")},
                      {s: ["walk-nodevice", "walk-device", "pert050-1"] for s in ("S01", "S02", "S03")}, SETTINGS,
                      r / "tables/impedance.tsv", r / "tables/impedance_summary.tsv", r / "figures/impedance.png",
                      r / "transparency/rmsd.tsv", versions=versions)


def test_the_file_step_writes_the_same_bytes_from_the_same_files(tmp_path):
    _write_results(tmp_path)
    first = (_front_page(tmp_path), (tmp_path / "results/report/front_page.html").read_bytes())
    again = _front_page(tmp_path)
    assert first[1] == again.encode() == (tmp_path / "results/report/front_page.html").read_bytes()
    png = (tmp_path / "results/figures/impedance.png").read_bytes()
    embedded = re.search(r'src="data:image/png;base64,([^"]+)"', again).group(1)
    assert base64.b64decode(embedded) == png  # the figure, byte for byte
    assert str(tmp_path) not in again and "results/figures" not in again  # no path on the page
    summary = pd.read_csv(tmp_path / "results/tables/impedance_summary.tsv", sep="\t")
    assert f'data-v="{float(summary.K_mean_nm_per_rad.iloc[0])!r}"' in again  # hip, 50 ms, from the file
    assert list(summary.joint) == ["hip"] * 3 + ["knee"] * 3 + ["ankle"] * 3 and (summary.n_subjects == 3).all()
    assert not list((tmp_path / "results/report").glob(".*partial"))  # written through the atomic writer


def _devtools():
    spec = importlib.util.spec_from_file_location("report_screenshot", ROOT / "benchmarks/report_screenshot.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_report_shows_the_headline_tables_on_its_first_screen(tmp_path):
    """The workflow's own report text (workflow/report/workflow.rst) in a Snakemake report of a small results set,
    opened in headless Chromium at 1400×900: both headline tables lie wholly within the first screen."""
    screen = _devtools()
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
        'rule all:\n    input:\n        "results/report/front_page.html",\n')
    res = subprocess.run([sys.executable, "-m", "snakemake", "--report", "report.html"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=120)
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
