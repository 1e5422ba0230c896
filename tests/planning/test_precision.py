"""The experiment planner (loper_analysis.planning.precision, steps.planning, ``loper-analysis plan``).

Known answers: Student's t with N - 1 degrees of freedom and the 1/N law of the prediction, the
identification's own sandwich covariance (a noise-free fit with the pilot's perturbed pairs' covariance
reports the predicted half-width), the null pairs' covariance when the pilot has no perturbed pairs, and
repeated synthetic experiments whose fits report the SD the planner predicted. For the conditional
counterfactual (the default): white noise through the leave-one-out weights (simulated), the mean weight of
n pairs (simulated), and at the pilot's own strides the fit's interval formula exactly.
"""

from __future__ import annotations

import logging
import math
import shutil
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml
from scipy.stats import t as student_t

from loper_analysis.cli import main
from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    cross_validated_covariance,
    identify_impedance,
    nuisance_projection,
    null_pair_errors,
    response_jacobian,
    simulate_response,
)
from loper_analysis.impedance.identification.impedance import IdentificationSettings, fit_onset
from loper_analysis.impedance.identification.intervals import t_quantile
from loper_analysis.impedance.responses import ResponseSettings, null_pair_windows
from loper_analysis.impedance.responses.conditional import shared_weight_terms, unit_scatter_variance
from loper_analysis.io.atomic import write_tsv
from loper_analysis.io.segment_table import write_segments
from loper_analysis.planning.covariance import (
    MIN_PERTURBED_PAIRS,
    StrideCovariance,
    conditional_stride_covariance,
    pool_onsets,
    stretch_covariances,
    stride_covariance,
)
from loper_analysis.planning.inputs import pilot_onset_series, pilot_perturbed_pairs, pulse_force_n, trial_stretches
from loper_analysis.planning.precision import precision_table, strides_needed, target_answer
from loper_analysis.planning.window import PlanSettings, planning_window
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment
from loper_analysis.synthetic.response import thigh_normal

#: The planner predicts for the study's matched strides, whose perturbed pairs' scatter the fit's intervals take.
MATCHED = ResponseSettings(counterfactual="matched_stride")
PLAN = PlanSettings(interval_scatter="perturbed_pairs")

HEIGHT_M, MASS_KG = 1.73, 64.9
ONSET_MS = 50
TRUTH = np.array([55.0, 3.5, 3.0, 0.10, 8.0, 0.3])
T95 = {9: 2.2621571628, 39: 2.0226909200}  # Student's t, 97.5 %, by degrees of freedom


@pytest.fixture(scope="module")
def params():
    return segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)


@pytest.fixture(scope="module")
def pilot(params):
    """A coordinate-level pilot: one trial with the device, its first 40 perturbed strides, null and perturbed pairs."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full, cut = perturbation_experiment([11, 0], params, HEIGHT_M, ONSET_MS, TRUTH, [40], angle_noise_sd_rad=0.001)
        null = null_pair_windows([full], ONSET_MS, MATCHED, source="pilot")
        pairs = pilot_perturbed_pairs([full], ONSET_MS, MATCHED)
    return full, cut[40], null, pairs


@pytest.fixture(scope="module")
def conditional_series(pilot):
    """The pilot's onset series with the conditional counterfactual (the default): null pairs and perturbed pairs."""
    full, _, _, _ = pilot
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pilot_onset_series([full], ONSET_MS, ResponseSettings())


@pytest.fixture(scope="module")
def stride_cov(params, pilot):
    _, _, null, pairs = pilot
    return stride_covariance(null, params, TRUTH, PLAN, perturbed_pairs=pairs)


def test_prediction_follows_one_over_n_and_student_t(stride_cov, pilot):
    """SD as 1/sqrt(N); the half-width with Student's t at N - 1 degrees of freedom, as the fit's intervals."""
    sc = stride_cov
    table = precision_table(sc, [10, 40], ONSET_MS, "P")
    assert len(table) == 3 * 2 * 2 and sc.dof is None and sc.scatter == "perturbed_pairs"
    assert (table["scatter"] == "perturbed_pairs").all() and (table["note"] == "").all()
    assert (table["n_perturbed_pairs"] == pilot[3]["n_pairs"]).all() and pilot[3]["n_pairs"] >= MIN_PERTURBED_PAIRS
    for (_, _), g in table.groupby(["joint", "parameter"]):
        sd10, sd40 = g.set_index("n_strides")["predicted_sd"].loc[[10, 40]]
        np.testing.assert_allclose(sd10 / sd40, 2.0, rtol=1e-12)
    t = table["n_strides"].map({10: T95[9], 40: T95[39]})
    np.testing.assert_allclose(table["ci95_half_width"] / table["predicted_sd"], t, rtol=1e-8)
    np.testing.assert_allclose(
        table["ci95_half_width_pct"], 100 * table["ci95_half_width"] / table["planned_value"].abs(), rtol=1e-12
    )


def test_prediction_is_the_fits_own_sandwich(params, pilot, stride_cov):
    """A noise-free fit given the null pairs' projection and the perturbed pairs' covariance / N (t at N - 1, as
    the fit's refit takes them) reports the predicted half-width."""
    _, _, null, pairs = pilot
    settings = PLAN
    sc = stride_cov
    window = planning_window(null, params, settings)
    # the pulse reaches the fit at 1 kHz: every RK4 step carries the exact impulse of the pulse's spline
    f = window.force_perturbed_n
    impulse = window.step_s * np.sum(f[:, 0] + 2 * f[:, 1] + 2 * f[:, 2] + f[:, 3], axis=0) / 6
    t_fine = np.linspace(window.time_s[0], window.time_s[-1], 20001)
    thigh = np.interp(t_fine, null["time_s"], null["q_unperturbed"].mean(axis=0)[:, 1])
    pulse = pulse_force_n(t_fine, 40.0, 0.1)[:, None] * thigh_normal(thigh)
    np.testing.assert_allclose(impulse, np.trapezoid(pulse, t_fine, axis=0), rtol=2e-3)
    errors = null_pair_errors(window, TRUTH, null)
    n = 20
    exact = replace(
        window,
        measured=simulate_response(window, TRUTH),
        residual_weight=nuisance_projection(errors, 6),
        noise_cov=np.cov(null_pair_errors(window, TRUTH, pairs), rowvar=False) / n,
    )
    fit = identify_impedance(exact, n_starts=2, extra_starts=TRUTH, ci_dof=n - 1)
    np.testing.assert_allclose(fit.estimate, TRUTH, rtol=1e-5, atol=1e-6)
    half = precision_table(sc, [n], ONSET_MS, settings=settings)["ci95_half_width"].to_numpy()
    # the upper half: intervals are cut at the lower bound 0, never at the upper bounds here
    np.testing.assert_allclose(fit.ci95_high - fit.estimate, half, rtol=0.02)


def test_strides_needed_is_the_smallest_count(params, pilot, stride_cov):
    """The smallest N whose half-width t(N - 1) sd_1 / sqrt(N) meets the target, found by scanning every N."""
    _, _, null, pairs = pilot
    sc = stride_cov
    for joint, p, pct in (("hip", "D", 15.0), ("knee", "K", 15.0), ("hip", "K", 2.0), ("ankle", "K", 60.0)):
        n = strides_needed(sc, joint, p, percent=pct)
        i = ["K_hip", "D_hip", "K_knee", "D_knee", "K_ankle", "D_ankle"].index(f"{p}_{joint}")
        target = pct / 100 * TRUTH[i]

        def half(k, i=i):
            return student_t.ppf(0.975, k - 1) * sc.sd[i] / math.sqrt(k)

        assert n == next(k for k in range(2, 100000) if half(k) <= target * (1 + 1e-12))
    # the fit's intervals from the null pairs' scatter: t at their M - 1 degrees of freedom, N = ceil((t sd_1 / h)^2)
    fixed = stride_covariance(null, params, TRUTH, PlanSettings(interval_scatter="null_pairs"), perturbed_pairs=pairs)
    assert fixed.dof == null["n_pairs"] - 1
    n_abs = strides_needed(fixed, "hip", "K", half_width=1.0)
    assert n_abs == math.ceil((student_t.ppf(0.975, null["n_pairs"] - 1) * fixed.sd[0] / 1.0) ** 2)
    text = target_answer(sc, "hip", "D", 175, percent=15)
    assert text.startswith("hip D at 175 ms: ±15 % (95 % CI) needs ") and "perturbed strides" in text


def test_pilot_without_perturbed_pairs_falls_back_to_the_null_pairs(params, pilot, stride_cov):
    """No perturbed pairs at the onset: C = cov(null-pair errors), the sandwich computed here; the rows say so."""
    full, _, null, pairs = pilot
    assert pilot_perturbed_pairs([full], 175, MATCHED) is None  # the pilot's strides are perturbed at 50 ms
    sc = stride_covariance(null, params, TRUTH, PLAN)
    window = planning_window(null, params)
    E = null_pair_errors(window, TRUTH, null)
    J = response_jacobian(window, TRUTH, PLAN.lower, PLAN.upper)
    WJ = nuisance_projection(E, 6) @ J
    M = np.linalg.pinv(WJ.T @ WJ) @ WJ.T @ nuisance_projection(E, 6)
    np.testing.assert_allclose(sc.covariance, M @ np.cov(E, rowvar=False) @ M.T, rtol=1e-6, atol=1e-12)
    assert sc.scatter == "null_pairs" and sc.n_perturbed_pairs == 0 and "no perturbed pairs" in sc.note
    table = precision_table(sc, [10], ONSET_MS)
    assert (table["scatter"] == "null_pairs").all() and table["note"].str.contains("no perturbed pairs").all()
    # the same sandwich of the perturbed pairs' errors; in this (gentle) lab they scatter more: each stride answers
    # the pulse about its own course
    Ep = null_pair_errors(window, TRUTH, pairs)
    np.testing.assert_allclose(stride_cov.covariance, M @ np.cov(Ep, rowvar=False) @ M.T, rtol=1e-6, atol=1e-12)
    print("perturbed / null pairs' SD (hip K, hip D, knee K, knee D):", np.round(stride_cov.sd[:4] / sc.sd[:4], 3))
    assert np.all(stride_cov.sd[:4] > 1.1 * sc.sd[:4])  # 1.18-1.55 here
    few = {
        k: (v[: MIN_PERTURBED_PAIRS - 1] if isinstance(v, np.ndarray) and v.ndim >= 2 else v) for k, v in pairs.items()
    }
    few["n_pairs"] = MIN_PERTURBED_PAIRS - 1
    assert stride_covariance(null, params, TRUTH, PLAN, perturbed_pairs=few).scatter == "null_pairs"


def test_pooled_scatter_is_the_weighted_mean_variance_ratio(stride_cov):
    """Two onsets: variance ratios 4 (11 pairs) and 1 (31 pairs) -> pooled (10*4 + 30*1) / 40 = 1.75 on every
    onset's null-pair sandwich, including an onset without perturbed pairs; one onset alone stays as it is."""
    null = np.diag([4.0, 0.25, 1.0, 0.01, 0.5, 0.002])
    p = np.array(TRUTH)
    a = StrideCovariance(4 * null, p, None, 130, "", 11, "perturbed_pairs", null)
    b = StrideCovariance(2 * null, p, None, 120, "", 31, "perturbed_pairs", 2 * null)
    c = StrideCovariance(
        3 * null, p, None, 125, "no perturbed pairs of the pilot at this onset: ...", 0, "null_pairs", 3 * null
    )
    pooled = pool_onsets({50: a, 175: b, 300: c})
    for onset, base in ((50, null), (175, 2 * null), (300, 3 * null)):
        np.testing.assert_allclose(pooled[onset].covariance, 1.75 * base, rtol=1e-12)
        assert pooled[onset].scatter == "pooled_perturbed_pairs"
        assert (
            pooled[onset].note
            == "perturbed/null pairs' variance ratio pooled over onsets 50, 175 ms (42 perturbed pairs)"
        )
    alone = pool_onsets({50: stride_cov})
    np.testing.assert_array_equal(alone[50].covariance, stride_cov.covariance)


def test_repeated_experiments_report_the_predicted_sd(params, pilot):
    """Eight new synthetic experiments (10 perturbed strides each): their fits' own CIs match the prediction.

    The fits' intervals come from the scatter of their own perturbed pairs (t at n_kept - 1), the prediction
    from the scatter of the pilot's perturbed pairs at the pilot's fitted impedance; over these repeats the RMS
    of the reported SD of hip and knee K and D lies within 30 % of the prediction (measured: 0.94-1.13 times).
    benchmarks/planner_check.py compares with the scatter of the estimates themselves over 60 repeats.
    """
    full, cut, null, pairs = pilot
    ident = IdentificationSettings(n_starts=3, interval_scatter="perturbed_pairs")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        logging.disable(logging.WARNING)
        try:
            pilot_fit = fit_onset([cut], params, ONSET_MS, "pilot", None, [full], MATCHED, ident)
            rows = pilot_fit.rows.set_index("joint")
            planned = np.array([rows.loc[j, parameter_column(p)] for j in JOINTS for p in ("K", "D")])
            sc = stride_covariance(null, params, np.clip(planned, 0, None), PLAN, perturbed_pairs=pairs)
            reported, kept = [], []
            for k in range(1, 9):
                f, c = perturbation_experiment(
                    [11, k], params, HEIGHT_M, ONSET_MS, TRUTH, [10], angle_noise_sd_rad=0.001
                )
                r = fit_onset([c[10]], params, ONSET_MS, f"R{k}", None, [f], MATCHED, ident).rows
                assert (r["noise_model"] == "null_pairs").all()
                r = r.set_index("joint")
                n_kept = int(r["n_strides"].iloc[0])
                high = r[[parameter_column(p, "ci95_high") for p in ("K", "D")]].loc[list(JOINTS)].to_numpy().ravel()
                est = r[[parameter_column(p) for p in ("K", "D")]].loc[list(JOINTS)].to_numpy().ravel()
                # the upper half: intervals are cut at the lower bound 0, never at the upper bounds here
                reported.append((high - est) / student_t.ppf(0.975, n_kept - 1))
                kept.append(n_kept)
        finally:
            logging.disable(logging.NOTSET)
    rms_reported = np.sqrt(np.mean(np.square(reported), axis=0))
    predicted = sc.sd * np.sqrt(np.mean(1.0 / np.array(kept)))
    ratio = predicted[:4] / rms_reported[:4]  # hip K, hip D, knee K, knee D
    print("predicted / reported (hip K, hip D, knee K, knee D):", np.round(ratio, 3))
    assert np.all(np.abs(ratio - 1) < 0.3), ratio


# --------------------------------------------------------------------------- bad input


def test_zero_or_negative_strides_are_refused(stride_cov):
    sc = stride_cov
    for bad in (0, -5):
        with pytest.raises(LoperInputError, match=f"stride count must be a whole number >= 1.*{bad}"):
            precision_table(sc, [10, bad], ONSET_MS)


def test_pulse_longer_than_the_window_is_refused():
    with pytest.raises(LoperInputError, match=r"pulse_duration_s = 0.3 s is longer than .*window_after_s = 0.25 s"):
        PlanSettings(pulse_duration_s=0.3)


def test_pilot_without_null_pairs_is_refused(params, pilot):
    _, _, null, _ = pilot
    few = {k: (v[:5] if isinstance(v, np.ndarray) and v.ndim >= 2 else v) for k, v in null.items()}
    with pytest.raises(LoperInputError, match=r"pilot: 5 null pair\(s\), fewer than impedance.null_pair_components"):
        stride_covariance(few, params, TRUTH)
    none = {k: (v[:0] if isinstance(v, np.ndarray) and v.ndim >= 2 else v) for k, v in null.items()}
    with pytest.raises(LoperInputError, match="no null pairs"):
        planning_window(none, params)


def test_planned_value_outside_bounds_is_refused(params, pilot):
    _, _, null, _ = pilot
    with pytest.raises(LoperInputError, match=r"planned D_knee = -0.1 N·m·s/rad lies outside"):
        stride_covariance(null, params, [55, 3.5, 3, -0.1, 8, 0.3])


# --------------------------------------------------------------------------- file layer and command


@pytest.fixture(scope="module")
def pilot_results(tmp_path_factory, params, pilot):
    """A results folder of a pilot S09: angle and stride tables, segment table, fit rows at 50 ms."""
    full, _, _, _ = pilot
    root = tmp_path_factory.mktemp("pilot") / "results"
    write_tsv(full["angles"], root / "ik/S09/pert050-1.angles.tsv")
    write_tsv(full["strides"], root / "strides/S09/pert050-1.strides.tsv")
    write_tsv(full["angles"], root / "ik/S09/pert050-2.angles.tsv")  # every stride perturbed: no null pair
    write_tsv(
        full["strides"].assign(perturbed=True, onset_s=full["strides"]["toe_off_s"] + 0.05),
        root / "strides/S09/pert050-2.strides.tsv",
    )
    write_tsv(full["angles"], root / "ik/S09/walk-nodevice.angles.tsv")  # excluded by default
    write_segments(params, root / "model/S09/segments.tsv")
    rows = pd.DataFrame(
        {
            "subject": "S09",
            "onset_ms": 50,
            "joint": list(JOINTS),
            parameter_column("K"): TRUTH[0::2],
            parameter_column("D"): TRUTH[1::2],
            "status": "ok",
            "reason": "",
        }
    )
    write_tsv(rows, root / "impedance/S09/050.tsv")
    return root


def test_plan_command_answers_the_target(
    pilot_results, pilot, params, conditional_series, tmp_path, capsys, monkeypatch
):
    monkeypatch.chdir(tmp_path)  # no config/config.yaml here: the library's defaults (onsets of the impedance rows)
    out = tmp_path / "plan.tsv"
    code = main(
        [
            "plan",
            "--results",
            str(pilot_results),
            "--subject",
            "S09",
            "--trials",
            "pert050-1",
            "--strides",
            "10",
            "40",
            "--target",
            "hip",
            "D",
            "15",
            "--out",
            str(out),
        ]
    )
    captured = capsys.readouterr()
    assert code == 0, captured.err
    table = pd.read_csv(out, sep="\t")
    assert len(table) == 12 and set(table["n_strides"]) == {10, 40} and set(table["onset_ms"]) == {50}
    # the library's default: the conditional counterfactual, planned from the onset's own strides
    sc = conditional_stride_covariance(conditional_series, params, TRUTH)
    # 10 strides: the pilot holds them four times over; its stretches of 10 plan for them
    full = {"name": "pert050-1", "angles": pilot[0]["angles"], "strides": pilot[0]["strides"]}
    by_count = stretch_covariances([full], ONSET_MS, [10, 40], params, TRUTH)
    assert set(by_count) == {10}
    expected = precision_table(sc, [10, 40], ONSET_MS, "S09", by_count=by_count)
    assert (table["scatter"] == "cross_validated_null_pairs").all()
    at_40 = table["n_strides"] == 40
    assert (table.loc[at_40, "n_perturbed_pairs"] == conditional_series["pairs"]["n_pairs"]).all()
    assert table.loc[~at_40, "note"].str.startswith("mean over 4 stretches of the pilot holding 10").all()
    # the pilot's tables went through TSV files (9 significant digits) on the way in
    np.testing.assert_allclose(table["predicted_sd"], expected["predicted_sd"], rtol=2e-4)
    n = strides_needed(sc, "hip", "D", percent=15)
    assert f"hip D at 50 ms: ±15 % (95 % CI) needs {n} perturbed strides" in captured.out


def test_plan_command_takes_the_working_directory_s_config_and_an_option_wins(pilot_results, tmp_path, monkeypatch):
    """config/config.yaml of the working directory sets the stride counts and onsets; --strides replaces them."""
    root = Path(__file__).resolve().parents[2]
    (tmp_path / "config").mkdir()
    (tmp_path / "workflow/schemas").mkdir(parents=True)
    shutil.copy(root / "workflow/schemas/config.schema.yaml", tmp_path / "workflow/schemas/config.schema.yaml")
    config = yaml.safe_load((root / "config/config.yaml").read_text())
    config["study"]["perturbation_onsets_ms"] = [50]
    config["planning"].update(strides=[7, 30], targets=[])
    (tmp_path / "config/config.yaml").write_text(yaml.safe_dump(config))
    monkeypatch.chdir(tmp_path)
    common = ["plan", "--results", str(pilot_results), "--subject", "S09", "--trials", "pert050-1"]
    assert main([*common, "--out", "config.tsv"]) == 0
    assert set(pd.read_csv(tmp_path / "config.tsv", sep="\t")["n_strides"]) == {7, 30}
    assert main([*common, "--strides", "9", "--out", "option.tsv"]) == 0
    assert set(pd.read_csv(tmp_path / "option.tsv", sep="\t")["n_strides"]) == {9}


@pytest.mark.parametrize(
    "args, message",
    [
        (["--strides", "0"], "--strides [0]: 0 is less than the minimum of 1 (the limits of planning.strides"),
        (["--duration-s", "0.5"], "pulse_duration_s = 0.5 s is longer than the fit window"),
        (
            ["--trials", "pert050-2"],
            "S09, onset 50 ms: 0 unperturbed stride(s) predicted from the others at this onset, fewer than "
            "impedance.null_pair_components + 3",
        ),
    ],
)
def test_plan_command_bad_input_exits_2(pilot_results, args, message, capsys):
    trials = [] if "--trials" in args else ["--trials", "pert050-1"]
    code = main(["plan", "--results", str(pilot_results), "--subject", "S09", *trials, *args])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("loper-analysis plan: ") and err.count("\n") == 1
    assert message in err


def test_failed_pilot_fit_stops_the_command_and_is_noted_by_the_workflow(pilot_results, tmp_path):
    """A pilot onset without an estimate: ``raise`` names it; ``note`` (the rule) writes rows without a prediction."""
    from loper_analysis.stages.planning.files import PilotFiles, PilotTrial
    from loper_analysis.stages.planning.step import PlanningSettings, plan

    failed = pd.DataFrame(
        {
            "subject": "S09",
            "onset_ms": 175,
            "joint": list(JOINTS),
            parameter_column("K"): np.nan,
            parameter_column("D"): np.nan,
            "status": "failed",
            "reason": "3 valid perturbed stride(s), fewer than 5: not fitted",
        }
    )
    write_tsv(failed, tmp_path / "175.tsv")
    root = pilot_results
    files = PilotFiles(
        trials={
            "pert050-1": PilotTrial(
                angles=root / "ik/S09/pert050-1.angles.tsv", strides=root / "strides/S09/pert050-1.strides.tsv"
            )
        },
        segments=root / "model/S09/segments.tsv",
        impedance=(root / "impedance/S09/050.tsv", tmp_path / "175.tsv"),
    )
    settings = PlanningSettings(onsets_ms=(50, 175), strides=(10,))
    with pytest.raises(
        LoperInputError,
        match=r"no fitted impedance of subject S09 at onset 175 ms for the hip "
        r"\(failed: 3 valid perturbed stride",
    ):
        plan(files, "S09", settings)
    table, _ = plan(files, "S09", settings, unplannable="note")
    late = table[table["onset_ms"] == 175]
    assert len(late) == 6 and late["predicted_sd"].isna().all() and late["note"].str.startswith("not planned").all()
    assert table.loc[table["onset_ms"] == 50, "predicted_sd"].notna().all()


def test_a_planned_value_near_zero_gets_an_answer_not_a_hang():
    """A relative target on a planned K of 1e-30 (a fit at its bound): bisection, not stepping, to the smallest
    N (about 7e62 here), and the answer says it is out of reach."""
    cov = np.diag([100.0, 1.0, 4.0, 0.01, 1.0, 0.01])
    for dof in (None, 120):
        sc = StrideCovariance(cov, np.array([55, 3.5, 1e-30, 0.1, 8, 0.3]), dof, 121)
        n = strides_needed(sc, "knee", "K", percent=15)
        t = 1.959964 if dof is None else t_quantile(dof)  # the fit's t: N - 1 (here ~1e62) or the null pairs' dof
        assert n == pytest.approx((t * 2.0 / 1.5e-31) ** 2, rel=1e-5)
        answer = target_answer(sc, "knee", "K", 50, percent=15)
        assert "needs more than 1,000,000 perturbed strides" in answer and "give a half_width" in answer
        # an ordinary target: the smallest N whose half-width t(N - 1 or dof) * sd / sqrt(N) meets 15 % of 3.5
        n = strides_needed(sc, "hip", "D", percent=15)
        meets = [sc.t95(m) * 1.0 / np.sqrt(m) <= 0.15 * 3.5 for m in (n - 1, n)]
        assert meets == [False, True]


def test_unit_scatter_variance_is_that_of_white_noise_through_the_leave_one_out_weights():
    """Known answer by simulation: the scatter (ddof 1) of the kept rows of (I - S) e for white e of unit variance."""
    rng = np.random.default_rng(3)
    n = 40
    S = rng.random((n, n))
    np.fill_diagonal(S, 0.0)
    S /= S.sum(axis=1, keepdims=True)
    keep = rng.random(n) > 0.2
    M = (np.eye(n) - S)[keep]
    draws = [np.var(M @ rng.standard_normal(n), ddof=1) for _ in range(20000)]
    assert abs(np.mean(draws) / unit_scatter_variance(S, keep) - 1) < 0.01


def test_shared_weight_terms_predict_the_mean_weight_of_n_pairs():
    """E |w_mean|^2 over n pairs drawn like the given ones = |mu|^2 + tr Sigma / n (simulated, 1 %)."""
    rng = np.random.default_rng(5)
    mu = rng.random(60) / 60
    draw = lambda k: mu + 0.02 * rng.standard_normal((k, 60))  # noqa: E731
    mu2, spread = shared_weight_terms(draw(4000))
    assert abs(mu2 / float(mu @ mu) - 1) < 0.05 and abs(spread / (60 * 0.02**2) - 1) < 0.05
    for n in (5, 30):
        simulated = np.mean([float(np.sum(draw(n).mean(axis=0) ** 2)) for _ in range(4000)])
        assert abs(simulated / (mu2 + spread / n) - 1) < 0.02


def test_conditional_plan_at_the_pilot_s_own_strides_is_the_fit_s_interval_formula(params, conditional_series):
    """For as many strides as the pilot kept, the planned SD is the fit's own: the cross-validated covariance
    of the null pairs' errors times their covariance scale (refit_with_null_pairs), at the same window."""
    from loper_analysis.planning.window import planning_window

    sc = conditional_stride_covariance(conditional_series, params, TRUTH)
    null, n = conditional_series["null_pairs"], int(conditional_series["pairs"]["n_pairs"])
    assert n >= MIN_PERTURBED_PAIRS and sc.scatter == "cross_validated_null_pairs" and sc.dof == null["n_pairs"] - 1
    window = planning_window(null, params, PlanSettings())
    J = response_jacobian(window, TRUTH, PlanSettings().lower, PlanSettings().upper)
    E = null_pair_errors(window, TRUTH, null)
    fit_cov = cross_validated_covariance(E, PlanSettings().null_pair_components, J, n) * null["covariance_scale"]
    np.testing.assert_allclose(sc.sd_of(n), np.sqrt(np.diag(fit_cov)), rtol=1e-9)
    # the candidates grow with the strides (the pilot's perturbation rate): the 1/N^2 part is their weights'
    # spread, and every prediction's weights sum to 1, so their mean has |mu|^2 >= 1 / candidates
    a, b = sc.variance_terms()
    V = cross_validated_covariance(E, PlanSettings().null_pair_components, J, 1) / null["unit_scatter_variance"]
    candidates = conditional_series["pairs"]["prediction_weights"].shape[1]
    assert np.all(b > 0) and np.all(a >= np.diag(V) * (1 + n / candidates) * (1 - 1e-9))


def test_conditional_strides_needed_is_the_smallest_count_that_meets_the_target(params, conditional_series):
    """The smallest N whose half-width (t with the null pairs' M - 1 degrees of freedom) meets the target."""
    sc = conditional_stride_covariance(conditional_series, params, TRUTH)
    for joint, parameter, i in (("hip", "D", 1), ("hip", "K", 0), ("knee", "K", 2)):
        target = 0.15 * TRUTH[i]
        n = strides_needed(sc, joint, parameter, percent=15)
        assert sc.half_width(n)[i] <= target * (1 + 1e-9) and (n == 1 or sc.half_width(n - 1)[i] > target)
        assert f"needs {n} perturbed strides" in target_answer(sc, joint, parameter, ONSET_MS, percent=15)


def test_a_stretch_holding_every_perturbed_stride_plans_as_the_whole_pilot(params, pilot, conditional_series):
    """One stretch with all the pilot's perturbed strides is the pilot: the same covariance to 1e-9."""
    full = pilot[0]
    every = int(full["strides"]["perturbed"].sum())
    whole = conditional_stride_covariance(conditional_series, params, TRUTH)
    alone = stretch_covariances([full], ONSET_MS, [every], params, TRUTH, response=ResponseSettings(), min_stretches=1)
    np.testing.assert_allclose(alone[every].sd_of(every), whole.sd_of(every), rtol=1e-9)
    assert stretch_covariances([full], ONSET_MS, [every], params, TRUTH) == {}  # held once: planned from the whole


def test_stretch_plan_is_the_mean_of_its_stretches_plans(params, pilot):
    """The plan for 10 strides: the mean over the pilot's stretches of 10 of each stretch's own variance terms."""
    full = pilot[0]
    own = [
        conditional_stride_covariance(pilot_onset_series([s], ONSET_MS, ResponseSettings()), params, TRUTH)
        for s in trial_stretches(full, 10)
    ]
    planned = stretch_covariances([full], ONSET_MS, [10], params, TRUTH)[10]
    for n in (10, 15):
        expected = np.mean([c.sd_of(n) ** 2 for c in own], axis=0)
        np.testing.assert_allclose(planned.sd_of(n) ** 2, expected, rtol=1e-12)
    assert planned.n_null_pairs == round(np.mean([c.n_null_pairs for c in own]))


def test_a_planned_second_rod_at_the_shank_sharpens_the_ankle_and_the_knee(params, pilot):
    """The same pilot's scatter with a 40 N pulse just above the ankle pushed with the thigh's: the predicted SD of
    the ankle's K and D falls below half the thigh rod's alone, the knee's and the hip's below it (measured at 20
    strides: ankle 0.14 and 0.08, knee 0.74 and 0.65, hip 0.85 and 0.55 of the thigh rod's SD; the fits on the
    validation's strides give 0.6 at the knee, ``tests/impedance/identification/test_two_rods.py``); the pilot's
    perturbed pairs (pushed at the thigh alone) are not taken, and the plan says why."""
    _, _, null, pairs = pilot
    one = stride_covariance(null, params, TRUTH, PLAN, perturbed_pairs=None)
    two = stride_covariance(null, params, TRUTH, replace(PLAN, shank_pulse_force_n=40.0), perturbed_pairs=pairs)
    ratio = two.sd_of(20) / one.sd_of(20)
    assert np.all(ratio[4:] < 0.5), ratio
    assert np.all(ratio[:4] < 1.0), ratio
    assert two.scatter == "null_pairs" and "pushed by 1 rod(s), the plan by 2" in two.note
    table = precision_table(two, [20], ONSET_MS, "S01", replace(PLAN, shank_pulse_force_n=40.0))
    assert set(table["shank_pulse_force_n"]) == {40.0}
