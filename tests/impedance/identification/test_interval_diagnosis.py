"""Fits whose null pairs' interval can miss the truth by more than it shows.

Rule 7 of ``joint_status``: a joint whose model response is smaller than its residual (a joint that barely moves in
the window) is ``not_identifiable``. A K or D whose perturbed pairs scatter beyond the interval's scatter (the
linearised jackknife over the averaged pairs, :func:`loper_analysis.impedance.identification.jackknife.jackknife_sd`,
against an F quantile) gets its interval from that scatter
(:func:`loper_analysis.impedance.identification.jackknife.widen_to_pair_scatter`). Each on a known case, the
jackknife against leave-one-out refits, and seeded sets of simulated strides with a known truth: a barely moving
ankle comes out ``not_identifiable`` with the reason, ankles whose strides answer with their own stiffness get the
interval their scatter says, a well-excited joint stays as it was.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from scipy.stats import beta, f
from scipy.stats import t as t_dist

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    MIN_RESPONSE_TO_RESIDUAL,
    PAIR_SCATTER_LEVEL,
    joint_status,
    response_and_residual_rms,
)
from loper_analysis.impedance.identification.impedance import impedance_rows
from loper_analysis.impedance.identification.intervals import f_quantile
from loper_analysis.impedance.identification.jackknife import jackknife_sd, widen_to_pair_scatter
from loper_analysis.impedance.identification.validation import perturbed_trial
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS, fit, window_for

LOWER, UPPER = (0.0, 0.0), (200.0, 10.0)
#: Hip, knee and ankle K (N·m/rad) and D (N·m·s/rad) of the seeded strides; the ankle's K varies by case.
HIP_KNEE = (60.0, 3.0, 5.0, 0.2)
#: The validation study's coordinate noise: uniform, 0.01 rad (m) peak to peak, on both strides.
NOISE_PEAK_TO_PEAK = SETTINGS.noise_peak_to_peak


def ok_interval(joint="ankle", **kw):
    """The status of an ankle row with a narrow interval inside its plausible range (no rule 1-6 finding)."""
    return joint_status(joint, (8.0, 0.3), (7.0, 0.25), (9.0, 0.35), 95.0, LOWER, UPPER, **kw)


def test_defaults():
    assert MIN_RESPONSE_TO_RESIDUAL == 1.0 and PAIR_SCATTER_LEVEL == 0.99


def test_rms_of_the_response_and_of_the_residual_per_joint():
    model = np.array([[3.0, 0.0, 1e-3], [4.0, 0.0, -1e-3]])
    measured = model + np.array([[1.0, 2.0, 0.0], [-1.0, -2.0, 0.0]])
    response, residual = response_and_residual_rms(measured, model)
    np.testing.assert_allclose(response, [np.sqrt(12.5), 0.0, 1e-3], rtol=1e-15)
    np.testing.assert_allclose(residual, [1.0, 2.0, 0.0], rtol=1e-15)
    with pytest.raises(LoperInputError):
        response_and_residual_rms(measured, model[:1])


def test_a_response_smaller_than_its_residual_is_not_identifiable():
    status, reason = ok_interval(response_rms_rad=0.6e-3, residual_rms_rad=1.2e-3)
    assert status == "not_identifiable"
    for words in ("ankle RMS 0.6 mrad", "0.5 times its residual's 1.2 mrad", "MIN_RESPONSE_TO_RESIDUAL", "K_ankle"):
        assert words in reason, (words, reason)


@pytest.mark.parametrize(
    "response, residual, expected",
    [
        (1.2e-3, 1.2e-3, "ok"),  # as large as the residual: the rule's edge is inside
        (1.19e-3, 1.2e-3, "not_identifiable"),
        (1e-3, 0.0, "ok"),  # a noise-free fit
        (0.0, 0.0, "ok"),  # no response and no residual: undefined, left to the VAF rule
        (np.nan, 1e-3, "ok"),
        (None, 1e-3, "ok"),
    ],
)
def test_the_edges_of_the_response_rule(response, residual, expected):
    assert ok_interval(response_rms_rad=response, residual_rms_rad=residual)[0] == expected


def test_the_least_response_ratio_can_be_given():
    kw = dict(response_rms_rad=1.5e-3, residual_rms_rad=1e-3)
    assert ok_interval(**kw)[0] == "ok"
    status, reason = ok_interval(**kw, min_response_to_residual=2.0)
    assert status == "not_identifiable" and "below 2 (MIN_RESPONSE_TO_RESIDUAL)" in reason
    with pytest.raises(LoperInputError, match="min_response_to_residual"):
        ok_interval(**kw, min_response_to_residual=0.0)


def test_the_f_quantile_is_scipy_s():
    for dof in ((9, 34), (11, 35), (49, 199), (1, 1)):
        assert f_quantile(*dof, 0.99) == pytest.approx(f.ppf(0.99, *dof), rel=1e-12)
    with pytest.raises(LoperInputError):
        f_quantile(0.5, 10, 0.99)


def _fit_with_sd(sd, ci_dof=34):
    """The seeded 8-pair fit of the validation's strides with its SDs replaced (intervals from them, t with
    ``ci_dof`` degrees of freedom): a fit whose intervals are known by hand."""
    from dataclasses import replace

    from loper_analysis.impedance.identification import bounded_interval

    _, _, full = _pairs([8.0] * 8, seed=3)
    sd = np.asarray(sd, dtype=float)
    low, high = bounded_interval(full.estimate, sd, ci_dof, SETTINGS.lower, SETTINGS.upper)
    return replace(full, sd=sd, ci_dof=ci_dof, ci95_low=low, ci95_high=high)


def test_pair_scatter_beyond_the_f_quantile_widens_that_interval_only():
    """10 pairs against 35 null pairs: F_0.99(9, 34) = 2.98. The ankle's K with a jackknife variance 1.01 times the
    quantile over its interval's gets the interval ``estimate +- t_0.975(9) sd_jk`` and a reason giving both SDs;
    its D at 0.99 times the quantile and every other parameter keep theirs; the estimate does not move."""
    limit = f.ppf(PAIR_SCATTER_LEVEL, 9, 34)
    sd = np.array([2.0, 0.1, 0.5, 0.01, 1.0, 0.02])
    fit = _fit_with_sd(sd)
    jk = sd.copy()
    jk[4], jk[5] = sd[4] * np.sqrt(1.01 * limit), sd[5] * np.sqrt(0.99 * limit)
    wide, notes = widen_to_pair_scatter(fit, (jk, 9), SETTINGS.lower, SETTINGS.upper)
    assert list(notes) == ["K_ankle"]
    text = notes["K_ankle"]
    assert "K_ankle: 95 % CI from the perturbed pairs' scatter (jackknife SD 1.74 N·m/rad, 1.7 times" in text
    assert f"F_0.99(9, 34) = {limit:.3g}, PAIR_SCATTER_LEVEL; t with 9 degrees of freedom" in notes["K_ankle"]
    np.testing.assert_array_equal(wide.estimate, fit.estimate)
    expected = np.array([False, False, False, False, True, False])
    np.testing.assert_array_equal(wide.sd, np.where(expected, jk, sd))
    half = 0.5 * (wide.ci95_high - wide.ci95_low)
    assert half[4] == pytest.approx(t_dist.ppf(0.975, 9) * jk[4], rel=1e-12)  # inside the bounds: symmetric
    np.testing.assert_array_equal(wide.ci95_low[~expected], fit.ci95_low[~expected])
    # a stricter level: the same ratio keeps the null pairs' interval
    assert widen_to_pair_scatter(fit, (jk, 9), SETTINGS.lower, SETTINGS.upper, level=0.999)[1] == {}
    # nothing to compare: an interval without information
    inf = _fit_with_sd([np.inf, 0.1, 0.5, 0.01, 1.0, 0.02])
    assert "K_hip" not in widen_to_pair_scatter(inf, (np.full(6, 50.0), 9), SETTINGS.lower, SETTINGS.upper)[1]
    with pytest.raises(LoperInputError, match="pair scatter level"):
        widen_to_pair_scatter(fit, (jk, 9), SETTINGS.lower, SETTINGS.upper, level=1.0)
    with pytest.raises(LoperInputError, match="jackknife SD must hold the fit's 6 parameters"):
        widen_to_pair_scatter(fit, (jk[:5], 9), SETTINGS.lower, SETTINGS.upper)


# --------------------------------------------------------------------------- seeded strides


@cache
def _trial(ankle_k: float):
    return perturbed_trial(PARAMS, np.array([*HIP_KNEE, ankle_k, 0.3]), SETTINGS)


def _noisy(trial, seed):
    """Unperturbed and perturbed coordinates of ``trial`` with the validation study's noise (seed ``seed``)."""
    rng = np.random.default_rng(seed)
    a = NOISE_PEAK_TO_PEAK / 2
    _, qu, qp = trial[:3]
    return qu + rng.uniform(-a, a, qu.shape), qp + rng.uniform(-a, a, qp.shape)


def _truth(ankle_k: float) -> dict:
    t = np.array([*HIP_KNEE, ankle_k, 0.3])
    return {j: {"K": t[2 * i], "D": t[2 * i + 1]} for i, j in enumerate(("hip", "knee", "ankle"))}


def _rows(ankle_k: float, seed: int, **kw):
    trial = _trial(ankle_k)
    qu, qp = _noisy(trial, seed)
    result = fit(window_for(trial, qu_measured=qu, qp_measured=qp), n_starts=3, seed=seed)
    return impedance_rows(result, "S01", 175, 10, _truth(ankle_k), lower=LOWER, upper=UPPER, **kw).set_index("joint")


def _clopper_pearson_high(k: int, n: int) -> float:
    return 1.0 if k == n else float(beta.ppf(0.975, k + 1, n - k))


SEEDS = range(20)


def test_a_barely_moving_ankle_is_not_identifiable_and_a_well_excited_one_stays_as_it_was():
    # A stiff ankle (150 N·m/rad) barely moves under the thigh's pulse: its response is below the validation noise
    # (or so far below it that the model describes less than no response: failed by the VAF floor as well)
    stiff = [_rows(150.0, s).loc["ankle"] for s in SEEDS]
    assert all(r["status"] in ("not_identifiable", "failed") for r in stiff)
    assert all("MIN_RESPONSE_TO_RESIDUAL" in r["reason"] for r in stiff)
    assert sum(r["status"] == "not_identifiable" for r in stiff) >= 15
    # ... and rightly: without the rule, the intervals of the rows still ok miss the truth far more often than 5 %
    plain = [_rows(150.0, s, min_response_to_residual=1e-12).loc["ankle"] for s in SEEDS]
    ok = [r for r in plain if r["status"] == "ok"]
    holds = sum(r["K_ci95_low_nm_per_rad"] <= 150.0 <= r["K_ci95_high_nm_per_rad"] for r in ok)
    assert len(ok) >= 5 and _clopper_pearson_high(holds, len(ok)) < 0.95, (holds, len(ok))
    # A well-excited ankle (8 N·m/rad): the rule finds nothing, every status is the other rules' own, and the
    # intervals hold the truth
    for s in SEEDS:
        rows = _rows(8.0, s)
        plain = _rows(8.0, s, min_response_to_residual=1e-12)
        assert "MIN_RESPONSE_TO_RESIDUAL" not in "".join(rows["reason"].fillna(""))
        assert list(rows["status"]) == list(plain["status"])
        a = rows.loc["ankle"]
        assert a["K_ci95_low_nm_per_rad"] <= 8.0 <= a["K_ci95_high_nm_per_rad"]
    assert sum(_rows(8.0, s).loc["ankle", "status"] == "ok" for s in SEEDS) >= 15


def _pairs(ankle_ks, seed: int):
    """Windows of the pairs (one per ankle K, each with its own noise) and of their mean, and the mean's fit."""
    trials = [_trial(k) for k in ankle_ks]
    noisy = [_noisy(t, 1000 * seed + i) for i, t in enumerate(trials)]
    windows = [window_for(t, qu_measured=qu, qp_measured=qp) for t, (qu, qp) in zip(trials, noisy)]
    qu_mean = np.mean([qu for qu, _ in noisy], axis=0)
    qp_mean = np.mean([qp for _, qp in noisy], axis=0)
    mean = window_for(trials[0], qu_measured=qu_mean, qp_measured=qp_mean)
    return windows, mean, fit(mean, n_starts=3, seed=seed)


def test_the_jackknife_is_that_of_leave_one_out_refits():
    """The linearised jackknife SD against the textbook one: each pair left out of the mean in turn and refitted."""
    windows, mean, full = _pairs([8.0] * 8, seed=3)
    sd, dof = jackknife_sd(mean, full.estimate, windows, lower=SETTINGS.lower, upper=SETTINGS.upper)
    assert dof == 7
    n = len(windows)
    trial = _trial(8.0)
    loo = []
    for p in range(n):
        noisy = [_noisy(trial, 3000 + i) for i in range(n) if i != p]
        w = window_for(
            trial, qu_measured=np.mean([q for q, _ in noisy], 0), qp_measured=np.mean([q for _, q in noisy], 0)
        )
        loo.append(fit(w, n_starts=3, seed=0).estimate)
    loo = np.array(loo)
    textbook = np.sqrt((n - 1) / n * np.sum((loo - loo.mean(0)) ** 2, axis=0))
    # The linear map (J^T J)^+ J^T leaves out the residual's own curvature term (sum r_k H_k), which the refits
    # hold: with the validation noise it moves the leave-one-out estimates by a few % of their scatter (7 % at the
    # ankle's K, at most 3 % elsewhere)
    np.testing.assert_allclose(sd, textbook, rtol=0.1)


def test_strides_that_answer_with_their_own_ankle_stiffness_get_the_interval_their_scatter_says():
    """Every stride the same but the ankle's K, 4 … 16 N·m/rad: the mean's interval (from the residual) shows the
    noise, the pairs show the strides' own ankles, and the ankle's K interval is taken from them (its row's reason
    says so); the hip's stays."""
    ks = np.linspace(4.0, 16.0, 10)
    widened, hip_widened, jack_var, expected_var = 0, 0, [], []
    for seed in range(5):
        windows, mean, full = _pairs(ks, seed)
        sd, dof = jackknife_sd(mean, full.estimate, windows, lower=SETTINGS.lower, upper=SETTINGS.upper)
        wide, notes = widen_to_pair_scatter(full, (sd, dof), SETTINGS.lower, SETTINGS.upper)
        rows = impedance_rows(wide, "S01", 175, len(ks), lower=LOWER, upper=UPPER, interval_notes=notes)
        rows = rows.set_index("joint")
        if "K_ankle" in notes:
            widened += 1
            assert wide.sd[4] == sd[4]
            assert "K_ankle: 95 % CI from the perturbed pairs' scatter" in rows.loc["ankle", "reason"]
        hip_widened += any(name.endswith("_hip") for name in notes)
        jack_var.append(sd[4] ** 2)
        # what the mean of the strides holds: their own ankle K's scatter over n, and the noise's (the interval)
        expected_var.append(np.var(ks, ddof=1) / len(ks) + full.sd[4] ** 2)
    # the jackknife variance of 5 x 10 pairs has 45 degrees of freedom: relative SE sqrt(2 / 45) = 21 %, 10.5 % of
    # the SD; within two of them
    assert np.sqrt(np.mean(jack_var) / np.mean(expected_var)) == pytest.approx(1.0, abs=0.21)
    assert widened == 5 and hip_widened == 0
    # the same strides with one ankle K: nothing to widen at any joint
    for seed in range(5):
        windows, mean, full = _pairs([8.0] * 10, seed)
        sd, dof = jackknife_sd(mean, full.estimate, windows, lower=SETTINGS.lower, upper=SETTINGS.upper)
        assert widen_to_pair_scatter(full, (sd, dof), SETTINGS.lower, SETTINGS.upper)[1] == {}
