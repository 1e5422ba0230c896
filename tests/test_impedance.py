"""Impedance table rows, statuses and the brace force direction."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.dynamics import segment_parameters_from_anthropometry
from loper_analysis.errors import LoperInputError
from loper_analysis.identification import identify_impedance
from loper_analysis.impedance import IMPEDANCE_COLUMNS, brace_force_direction, impedance_rows, status_rows
from loper_analysis.validation import ValidationSettings, perturbed_trial, validation_window

TRUTH = (60.0, 3.0, 5.0, 0.2, 20.0, 0.5)


@pytest.fixture(scope="module")
def fit():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    settings = ValidationSettings(n_starts=4)
    window = validation_window(params, settings, perturbed_trial(params, TRUTH, settings))
    return identify_impedance(window, n_starts=4, seed=1)


def test_rows_carry_estimates_truth_and_errors(fit):
    truth = {"hip": {"K": 60.0, "D": 3.0}, "knee": {"K": 5.0, "D": 0.2}, "ankle": {"K": 20.0, "D": 0.5}}
    rows = impedance_rows(fit, "S01", 50, 12, truth)
    assert list(rows.columns) == list(IMPEDANCE_COLUMNS) and list(rows.joint) == ["hip", "knee", "ankle"]
    np.testing.assert_allclose(rows.K, TRUTH[0::2], atol=0.05)
    np.testing.assert_allclose(rows.D, TRUTH[1::2], atol=0.005)
    np.testing.assert_allclose(rows.K_error, rows.K - rows.K_true)
    assert (rows.status == "ok").all() and (rows.n_strides == 12).all()
    assert (rows.K_ci95_low <= rows.K).all() and (rows.K <= rows.K_ci95_high).all()


def test_statuses(fit):
    wide = replace(fit, ci95_low=fit.ci95_low - np.array([0, 0, 0, 0, 150.0, 0]))
    rows = impedance_rows(wide, "S01", 175, 9)
    assert list(rows.status) == ["ok", "ok", "not_identifiable"] and "CI width K" in rows.reason.iloc[2]
    assert rows.K_true.isna().all()  # a recorded subject
    failed = impedance_rows(replace(fit, success=False, message="max iterations"), "S01", 175, 9)
    assert (failed.status == "failed").all() and failed.reason.str.contains("max iterations").all()
    missing = status_rows("S02", 300, "missing", "no trial of this onset")
    assert len(missing) == 3 and missing.K.isna().all() and (missing.status == "missing").all()


def test_brace_normal_is_perpendicular_and_forward():
    q = np.array([0.0, 0.4, -0.3])  # thigh segment angles (positive: knee backward)
    hip = np.zeros((3, 3))
    axis = np.stack([-np.sin(q), -np.cos(q), np.zeros(3)], axis=-1)  # hip -> knee
    X = np.stack([hip + 0.2 * axis, hip + 0.35 * axis], axis=1)  # proximal, distal
    n = brace_force_direction(X, ["LBRA_P", "LBRA_D"])
    np.testing.assert_allclose(n, np.stack([np.cos(q), -np.sin(q)], axis=-1), atol=1e-12)
    with pytest.raises(LoperInputError, match=r"trial.trc: brace marker\(s\) \['LBRA_D'\]"):
        brace_force_direction(X[:, :1], ["LBRA_P"], source="trial.trc")


def test_onset_without_trials_is_reported_missing(tmp_path):
    from loper_analysis.impedance import fit_subject_onset
    from loper_analysis.synthetic.subjects import write_truth

    write_truth(tmp_path / "truth.yaml", {"subject": "S01", "sex": "male", "age_yr": 26, "height_m": 1.8, "mass_kg": 72},
                {175: {j: {"K": 40.0, "D": 2.0} for j in ("hip", "knee", "ankle")}})
    out = [tmp_path / n for n in ("r.tsv", "c.tsv", "f.tsv", "k.tsv")]
    rows = fit_subject_onset([], tmp_path / "segments.tsv", 175, "S01", *out, truth_yaml=tmp_path / "truth.yaml")
    assert (rows.status == "missing").all() and rows.K.isna().all() and (rows.K_true == 40.0).all()
    assert all(p.is_file() for p in out)
    import pandas as pd

    assert pd.read_csv(out[2], sep="\t").status.tolist() == ["missing"] * 3


def test_summary_and_literature_rows():
    import pandas as pd

    from loper_analysis.impedance import impedance_summary, literature_table

    rows = []
    for subject, k, d in (("S01", 50.0, 3.0), ("S02", 60.0, 5.0)):
        rows.append(status_rows(subject, 50, "ok", "").assign(K=k, D=d, vaf_pct=99.0, K_true=55.0, D_true=3.0))
    rows.append(status_rows("S03", 50, "missing", "no trial"))
    table = pd.concat(rows, ignore_index=True)
    table["K_error"], table["D_error"] = table.K - table.K_true, table.D - table.D_true
    summary = impedance_summary(table)
    hip = summary[summary.joint == "hip"].iloc[0]
    assert hip.n_subjects == 2 and hip.K_mean == 55.0 and hip.K_sd == pytest.approx(np.sqrt(50.0))
    assert hip.K_within_tolerance == 1.0  # |5| <= 0.1 * 55
    assert hip.D_within_tolerance == 0.5  # 0 ok, 2 > 0.15 * 3
    lit = literature_table(summary)
    ours = lit[lit.source.str.startswith("this pipeline") & (lit.joint == "hip")].iloc[0]
    assert (ours.K_low, ours.K_high, ours.D_low, ours.D_high) == (55.0, 55.0, 4.0, 4.0)
    assert len(lit) == 9
