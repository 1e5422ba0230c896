"""identification/across_subjects.py: the across-subject summary of impedance rows built here with known
estimates (means, SDs, the random-effects interval and the truth's recovery) and the literature table beside it."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.impedance.identification.across_subjects import impedance_summary, literature_table
from loper_analysis.impedance.identification.impedance import status_rows


def test_summary_and_literature_rows():
    rows = []
    for subject, k, d in (("S01", 50.0, 3.0), ("S02", 60.0, 5.0)):
        rows.append(
            status_rows(subject, 50, "ok", "").assign(
                K_nm_per_rad=k,
                D_nms_per_rad=d,
                K_se_nm_per_rad=2.0,
                D_se_nms_per_rad=0.5,
                vaf_pct=99.0,
                K_true_nm_per_rad=55.0,
                D_true_nms_per_rad=3.0,
            )
        )
    rows.append(status_rows("S03", 50, "missing", "no trial"))
    table = pd.concat(rows, ignore_index=True)
    table["K_error_nm_per_rad"] = table.K_nm_per_rad - table.K_true_nm_per_rad
    table["D_error_nms_per_rad"] = table.D_nms_per_rad - table.D_true_nms_per_rad
    summary = impedance_summary(table)
    hip = summary[summary.joint == "hip"].iloc[0]
    assert hip.n_subjects == 2 and hip.K_mean_nm_per_rad == 55.0
    assert hip.K_sd_nm_per_rad == pytest.approx(np.sqrt(50.0))
    assert hip.K_fraction_within_tolerance == 1.0  # |5| <= 0.1 * 55
    assert hip.D_fraction_within_tolerance == 0.5  # 0 ok, 2 > 0.15 * 3
    # random effects, equal standard errors below the spread: the t interval of 50 and 60 (t(0.975, 1) = 12.71)
    half = 12.706204736174707 * np.sqrt(50.0) / np.sqrt(2.0)
    assert hip.K_group_mean_nm_per_rad == pytest.approx(55.0, rel=1e-12)
    assert hip.K_group_ci95_high_nm_per_rad == pytest.approx(55.0 + half, rel=1e-9)
    assert hip.K_group_ci95_low_nm_per_rad == 0.0  # 55 - 63.5, cut at 0 as the fits' own intervals
    assert hip.K_between_sd_nm_per_rad == pytest.approx(np.sqrt(50.0 - 4.0), rel=1e-12)
    assert hip.K_true_mean_nm_per_rad == 55.0 and hip.K_group_truth_in_ci95
    lit = literature_table(summary)
    ours = lit[lit.source.str.startswith("this pipeline") & (lit.joint == "hip")].iloc[0]
    assert (ours.K_low_nm_per_rad, ours.K_high_nm_per_rad, ours.D_low_nms_per_rad, ours.D_high_nms_per_rad) == (
        55.0,
        55.0,
        4.0,
        4.0,
    )
    assert len(lit) == 9


def test_summary_leaves_out_estimates_on_an_upper_bound():
    """The campaign's case: a bad trial's knee K at the 200 N·m/rad bound would pull the knee mean from 3 to 68."""
    rows = [
        status_rows(s, 50, "ok", "").assign(
            K_nm_per_rad=k, D_nms_per_rad=0.1, K_se_nm_per_rad=1.0, D_se_nms_per_rad=0.05, vaf_pct=99.0
        )
        for s, k in (("S01", 3.0), ("S02", 3.0), ("S03", 200.0))
    ]
    table = pd.concat(rows, ignore_index=True)
    table.loc[table.subject == "S03", "status"] = "not_identifiable"
    knee = impedance_summary(table).set_index("joint").loc["knee"]
    assert knee.K_mean_nm_per_rad == pytest.approx(206.0 / 3)
    knee = impedance_summary(table, upper_bounds=(200.0, 10.0)).set_index("joint").loc["knee"]
    assert knee.n_subjects == 2 and knee.K_mean_nm_per_rad == 3.0
    assert impedance_summary(table, upper_bounds=(200.0, 0.1)).empty  # every D on its bound: nothing left


def test_summary_cuts_the_group_interval_at_the_lower_bound():
    """Knee K -0.6, 0.2, 0.1 N·m/rad (SE 0.5 each; signed bounds): the random-effects mean -0.1 and its interval
    stay below 0 with a lower bound of -20, and are cut at 0 with the default bound (the fits' own rule)."""
    rows = [
        status_rows(s, 175, "ok", "").assign(
            K_nm_per_rad=k, D_nms_per_rad=0.1, K_se_nm_per_rad=0.5, D_se_nms_per_rad=0.05, vaf_pct=99.0
        )
        for s, k in (("S01", -0.6), ("S02", 0.2), ("S03", 0.1))
    ]
    table = pd.concat(rows, ignore_index=True)
    signed = impedance_summary(table, lower_bounds=(-20.0, -1.0)).set_index("joint").loc["knee"]
    assert signed.K_group_mean_nm_per_rad == pytest.approx(-0.1)
    assert signed.K_group_ci95_low_nm_per_rad < -0.1 < signed.K_group_ci95_high_nm_per_rad
    clipped = impedance_summary(table).set_index("joint").loc["knee"]
    assert clipped.K_group_ci95_low_nm_per_rad == 0.0 and clipped.K_group_mean_nm_per_rad == pytest.approx(-0.1)


def test_summary_keeps_uninformative_rows_and_counts_them():
    """Knee D 0.10, 0.12 (ok) and 0.01 whose interval 0 ... 0.3 holds 0 and the study's range (not_identifiable):
    the mean stays (0.10 + 0.12 + 0.01) / 3 = 0.0767, not the 0.11 of the informative rows alone, and the count
    says 1."""
    rows = [
        status_rows(s, 175, st, "").assign(
            K_nm_per_rad=1.0, D_nms_per_rad=d, K_se_nm_per_rad=0.5, D_se_nms_per_rad=se, vaf_pct=99.0
        )
        for s, d, se, st in (
            ("S01", 0.10, 0.01, "ok"),
            ("S02", 0.12, 0.01, "ok"),
            ("S03", 0.01, 0.15, "not_identifiable"),
        )
    ]
    knee = (
        impedance_summary(pd.concat(rows, ignore_index=True), upper_bounds=(200.0, 10.0)).set_index("joint").loc["knee"]
    )
    assert knee.n_subjects == 3 and knee.n_not_identifiable == 1
    assert knee.D_mean_nms_per_rad == pytest.approx(0.23 / 3)
    # the random-effects mean weighs the uninformative fit by its standard error, not by leaving it out:
    # DerSimonian-Laird Q = 2.444 on 2 df, tau^2 = 0.444 / 10066.5 = 4.41e-5, weights 6940, 6940, 44.4
    assert knee.D_group_mean_nms_per_rad == pytest.approx(0.10968, abs=1e-5)
    assert knee.D_group_ci95_low_nms_per_rad < 0.10 and knee.D_group_ci95_high_nms_per_rad > 0.12


def _fitted(subject: str, onset: int, k: float, d: float) -> pd.DataFrame:
    return status_rows(subject, onset, "ok", "").assign(
        K_nm_per_rad=k, D_nms_per_rad=d, K_se_nm_per_rad=1.0, D_se_nms_per_rad=0.1, vaf_pct=95.0
    )


def test_summary_rows_run_by_joint_then_onset_without_truth_columns():
    table = pd.concat(
        [_fitted("S01", 300, 10.0, 1.0), _fitted("S01", 50, 30.0, 2.0), _fitted("S02", 50, 50.0, 4.0)],
        ignore_index=True,
    )
    summary = impedance_summary(table)
    assert list(zip(summary.joint, summary.onset_ms)) == [
        ("hip", 50),
        ("hip", 300),
        ("knee", 50),
        ("knee", 300),
        ("ankle", 50),
        ("ankle", 300),
    ]
    hip50 = summary.iloc[0]
    assert (hip50.n_subjects, hip50.K_min_nm_per_rad, hip50.K_max_nm_per_rad, hip50.D_mean_nms_per_rad) == (
        2,
        30.0,
        50.0,
        3.0,
    )
    assert hip50.vaf_pct_mean == 95.0 and "K_error_mean_nm_per_rad" not in summary.columns
    assert np.isnan(summary.iloc[1].K_sd_nm_per_rad)  # one subject: no SD


def test_literature_table_adds_the_range_over_onsets_of_each_joint():
    table = pd.concat(
        [_fitted("S01", 50, 40.0, 2.0), _fitted("S01", 175, 70.0, 3.0), _fitted("S01", 300, 55.0, 2.5)],
        ignore_index=True,
    )
    lit = literature_table(impedance_summary(table))
    assert len(lit) == 9
    ours = lit.iloc[7:].set_index("joint")
    assert list(ours.index) == ["hip", "knee"]
    assert (set(ours.source)) == {"this pipeline: swing phase, across-subject mean over onsets"}
    assert tuple(
        ours.loc["hip", ["K_low_nm_per_rad", "K_high_nm_per_rad", "D_low_nms_per_rad", "D_high_nms_per_rad"]]
    ) == (
        40.0,
        70.0,
        2.0,
        3.0,
    )
    imposed = lit.iloc[4]
    assert (imposed.source, imposed.joint, imposed.K_low_nm_per_rad, imposed.K_high_nm_per_rad) == (
        "position perturbation, imposed motion",
        "knee",
        25.0,
        30.0,
    )
    assert imposed[["D_low_nms_per_rad", "D_high_nms_per_rad"]].isna().all()  # not reported
    # nothing fitted: the literature alone
    empty = literature_table(impedance_summary(status_rows("S01", 50, "missing", "no trial")))
    assert len(empty) == 7 and not empty.source.str.startswith("this pipeline").any()
