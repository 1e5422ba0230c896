"""The headline tables of a run (loper_analysis.report.headline): CIs, truth recovery, verdicts, and bad tables."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.across_subjects import impedance_summary
from loper_analysis.reference import STUDY_DEVICE
from loper_analysis.report.headline import (
    ci_coverage_p,
    device_comparison,
    impedance_summary_ci,
    transparency_verdict,
    truth_recovery,
    validation_verdict,
)
from tests.headline_tables import impedance_row, impedance_table, validation_summary

#: t(0.975, 2): the 95 % quantile factor of a mean over 3 subjects
T_975_2 = 4.302652729749464


def test_the_across_subject_ci_is_students_t_when_subjects_differ_more_than_their_fits():
    """Three hip fits K 8, 10, 12 N·m/rad (SD 2 between subjects) with equal standard errors of 0.49 (D 0.30,
    0.33, 0.36 with 0.005): the random-effects interval is the t interval of the three estimates; one knee fit
    has no interval."""
    rows = [
        impedance_row(s, 50, "hip", k, 0.3 + 0.03 * i, (k - 1.0, k + 1.0), (0.29 + 0.03 * i, 0.31 + 0.03 * i))
        for i, (s, k) in enumerate((("S1", 8.0), ("S2", 10.0), ("S3", 12.0)))
    ]
    rows.append(impedance_row("S1", 50, "knee", 5.0, 0.1, (4.0, 6.0), (0.05, 0.15)))
    ci = impedance_summary_ci(impedance_summary(pd.DataFrame(rows)), "s.tsv")
    half_k = T_975_2 * 2.0 / math.sqrt(3)  # 4.968 N·m/rad
    assert ci.loc[0, "K_mean_nm_per_rad"] == pytest.approx(10.0, rel=1e-12)
    assert ci.loc[0, "K_ci95_low_nm_per_rad"] == pytest.approx(10.0 - half_k, rel=1e-12)
    assert ci.loc[0, "K_ci95_high_nm_per_rad"] == pytest.approx(14.968275, abs=1e-6)
    assert ci.loc[0, "D_ci95_high_nms_per_rad"] == pytest.approx(0.33 + T_975_2 * 0.03 / math.sqrt(3), rel=1e-9)
    assert math.isnan(ci.loc[1, "K_ci95_low_nm_per_rad"])  # one subject: no interval
    assert ci.loc[1, "K_mean_nm_per_rad"] == 5.0 and ci.loc[0, "n_subjects"] == 3


def test_truth_recovery_counts_the_known_errors():
    truth = truth_recovery(impedance_table(), "i.tsv").set_index("joint")
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
    rmsd = pd.DataFrame(
        {
            "subject": ["S1", "S2", "all", "S1", "S2", "all"],
            "phase": ["stance"] * 3 + ["swing"] * 3,
            "joint": ["hip"] * 6,
            "rmsd_rad": [0.02, 0.03, 0.025, 0.07, np.nan, 0.07],
            "isv_ave_rad": [0.04, 0.04, 0.04, 0.06, np.nan, 0.06],
            "transparent": [True, True, True, False, np.nan, False],
            "study_rmsd_rad": 0.024,
            "study_isv_ave_rad": 0.04,
        }
    )
    tr = transparency_verdict(rmsd, "r.tsv")
    assert tr.transparent.tolist() == [True, False]
    assert tr.n_subjects.tolist() == [2, 1] and tr.n_subjects_transparent.tolist() == [2, 0]
    device = pd.DataFrame(
        {
            "metric": ["bandwidth_hz", "rise_time_ms", "overshoot_pct", "steady_state_40n_n", "rise_time_ms_at_20n"],
            "value": [42.9, 10.0, 30.5, 36.0, 9.7],
        }
    )
    dev = device_comparison(device, "d.tsv").set_index("metric")
    assert list(dev.index) == list(STUDY_DEVICE)
    assert dev.loc["bandwidth_hz", "difference_pct"] == pytest.approx(10.0)  # 42.9 Hz against the study's 39
    assert dev.loc["rise_time_ms", "study_value"] == 10.0
    val = validation_verdict(validation_summary(), "v.tsv").set_index("parameter")
    assert val.loc["K", "max_error"] == 0.02 and val.loc["D", "min_error"] == -0.001
    assert val.within_study.all() and val.loc["K", "n_combinations"] == 729


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (
            lambda: impedance_summary_ci(pd.DataFrame({"joint": ["hip"]}), "s.tsv"),
            "s.tsv: impedance summary: column(s) ['onset_ms', 'n_subjects'",
        ),
        (
            lambda: impedance_summary_ci(
                pd.DataFrame(
                    {
                        "joint": ["hip"],
                        "onset_ms": [50],
                        "n_subjects": [0],
                        "n_not_identifiable": [0],
                        "K_group_mean_nm_per_rad": [1.0],
                        "K_group_ci95_low_nm_per_rad": [0.5],
                        "K_group_ci95_high_nm_per_rad": [1.5],
                        "D_group_mean_nms_per_rad": [1.0],
                        "D_group_ci95_low_nms_per_rad": [0.5],
                        "D_group_ci95_high_nms_per_rad": [1.5],
                        "vaf_pct_mean": [90.0],
                    }
                ),
                "s.tsv",
            ),
            "s.tsv: row 0 (hip 50 ms): n_subjects must be an integer >= 1, got 0",
        ),
        (
            lambda: transparency_verdict(
                pd.DataFrame(
                    {
                        "subject": ["all"],
                        "phase": ["swing"],
                        "joint": ["hip"],
                        "rmsd_rad": [0.1],
                        "isv_ave_rad": [0.2],
                        "transparent": ["maybe"],
                        "study_rmsd_rad": [0.1],
                        "study_isv_ave_rad": [0.1],
                    }
                ),
                "r.tsv",
            ),
            "r.tsv: row 0: column 'transparent' must be True, False or blank, got 'maybe'",
        ),
        (
            lambda: device_comparison(pd.DataFrame({"metric": ["bandwidth_hz"], "value": [39.0]}), "d.tsv"),
            "d.tsv: device summary: metric 'rise_time_ms' missing",
        ),
        (
            lambda: device_comparison(pd.DataFrame({"metric": list(STUDY_DEVICE), "value": ["x", 1, 1, 1]}), "d.tsv"),
            "d.tsv: value of metric 'bandwidth_hz' must be a number, got 'x'",
        ),
        (
            lambda: truth_recovery(impedance_table().assign(K_ci95_low_nm_per_rad="?"), "i.tsv"),
            "i.tsv: fitted rows: column 'K_ci95_low_nm_per_rad', row 0 must be a number, got '?'",
        ),
    ],
)
def test_bad_tables_are_refused_naming_file_field_and_value(call, message):
    with pytest.raises(LoperInputError) as err:
        call()
    assert message in str(err.value)
