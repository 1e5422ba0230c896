"""Impedance table rows (loper_analysis.impedance.identification.impedance): estimates, truth, statuses, the brace force
direction and an onset without trials."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import identify_impedance
from loper_analysis.impedance.identification.impedance import (
    IMPEDANCE_COLUMNS,
    fit_onset,
    impedance_rows,
    status_rows,
)
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    perturbed_trial,
    validation_window,
)
from loper_analysis.impedance.responses.rod_directions import brace_force_direction
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry

TRUTH = (60.0, 3.0, 5.0, 0.2, 20.0, 0.5)
TRUTH_BY_JOINT = {"hip": {"K": 60.0, "D": 3.0}, "knee": {"K": 5.0, "D": 0.2}, "ankle": {"K": 20.0, "D": 0.5}}


@pytest.fixture(scope="module")
def fit():
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    settings = ValidationSettings(n_starts=4)
    window = validation_window(params, settings, perturbed_trial(params, TRUTH, settings))
    return identify_impedance(window, n_starts=4, seed=1)


def test_rows_carry_estimates_truth_and_errors(fit):
    rows = impedance_rows(fit, "S01", 50, 12, TRUTH_BY_JOINT)
    assert list(rows.columns) == list(IMPEDANCE_COLUMNS) and list(rows.joint) == ["hip", "knee", "ankle"]
    np.testing.assert_allclose(rows.K_nm_per_rad, TRUTH[0::2], atol=0.05)
    np.testing.assert_allclose(rows.D_nms_per_rad, TRUTH[1::2], atol=0.005)
    np.testing.assert_allclose(rows.K_error_nm_per_rad, rows.K_nm_per_rad - rows.K_true_nm_per_rad)
    np.testing.assert_allclose(rows.D_error_nms_per_rad, rows.D_nms_per_rad - rows.D_true_nms_per_rad)
    assert (rows.status == "ok").all() and (rows.n_strides == 12).all()
    assert (rows.K_ci95_low_nm_per_rad <= rows.K_nm_per_rad).all()
    assert (rows.K_nm_per_rad <= rows.K_ci95_high_nm_per_rad).all()


def test_rows_carry_the_fit_summary(fit):
    """The unweighted sum of squared errors and the start counts of the fit, the same on every joint's row."""
    rows = impedance_rows(fit, "S01", 50, 12, TRUTH_BY_JOINT)
    assert (rows.sum_sq_error_rad2 == fit.sum_sq_error_rad2).all()
    assert (rows.n_starts == fit.n_starts).all() and (rows.n_starts_at_best == fit.n_starts_at_best).all()


def test_statuses(fit):
    wide = replace(fit, ci95_low=fit.ci95_low - np.array([0, 0, 0, 0, 150.0, 0]))
    rows = impedance_rows(wide, "S01", 175, 9, max_ci_fraction=0.5)
    assert list(rows.status) == ["ok", "ok", "not_identifiable"] and "CI width K" in rows.reason.iloc[2]
    # by default only an unbounded interval is too wide; this one is flagged by what it holds (0 and the range)
    default = impedance_rows(wide, "S01", 175, 9)
    assert list(default.status) == ["ok", "ok", "not_identifiable"]
    assert "holds both 0 and the plausible range" in default.reason.iloc[2]
    assert "CI width" not in default.reason.iloc[2]
    assert rows.K_true_nm_per_rad.isna().all()  # a recorded subject
    failed = impedance_rows(replace(fit, success=False, message="max iterations"), "S01", 175, 9)
    assert (failed.status == "failed").all() and failed.reason.str.contains("max iterations").all()
    missing = status_rows("S02", 300, "missing", "no trial of this onset")
    assert len(missing) == 3 and missing.K_nm_per_rad.isna().all() and (missing.status == "missing").all()


def test_brace_normal_is_perpendicular_and_forward():
    q = np.array([0.0, 0.4, -0.3])  # thigh segment angles (positive: knee backward)
    hip = np.zeros((3, 3))
    axis = np.stack([-np.sin(q), -np.cos(q), np.zeros(3)], axis=-1)  # hip -> knee
    X = np.stack([hip + 0.2 * axis, hip + 0.35 * axis], axis=1)  # proximal, distal
    n = brace_force_direction(X, ["LBRA_P", "LBRA_D"])
    np.testing.assert_allclose(n, np.stack([np.cos(q), -np.sin(q)], axis=-1), atol=1e-12)
    with pytest.raises(LoperInputError, match=r"trial.trc: brace marker\(s\) \['LBRA_D'\]"):
        brace_force_direction(X[:, :1], ["LBRA_P"], source="trial.trc")


def test_onset_without_trials_is_reported_missing():
    truth = {j: {"K": 40.0, "D": 2.0} for j in ("hip", "knee", "ankle")}
    result = fit_onset([], None, 175, "S01", truth=truth)
    rows = result.rows
    assert (rows.status == "missing").all() and rows.K_nm_per_rad.isna().all()
    assert (rows.K_true_nm_per_rad == 40.0).all() and (rows.D_true_nms_per_rad == 2.0).all()
    assert result.counts.status.tolist() == ["missing"] and result.response.empty
    assert list(result.curves.columns) == ["time_s"] and result.curves.empty


def test_rows_carry_each_parameter_s_strongest_coupling_with_another_joint(fit):
    """Per K and D, the other joint's parameter with the largest |correlation| in the fit's matrix, and its value."""
    rows = impedance_rows(fit, "S01", 50, 12, TRUTH_BY_JOINT).set_index("joint")
    names = ("K_hip", "D_hip", "K_knee", "D_knee", "K_ankle", "D_ankle")
    for i, name in enumerate(names):
        joint, p = name.split("_")[1], name.split("_")[0]
        others = [k for k in range(6) if k // 2 != i // 2]
        k = others[int(np.argmax(np.abs(fit.correlation[i, others])))]
        assert rows.loc[joint, f"{p}_coupled_with"] == names[k]
        assert rows.loc[joint, f"{p}_coupling_correlation"] == fit.correlation[i, k]
    assert -1.0 <= rows.K_coupling_correlation.min() and rows.K_coupling_correlation.max() <= 1.0
