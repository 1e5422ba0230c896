"""Parts of one onset's fit (identification.onset_fit): the mean response's window against its analytic
deviation, the null pairs' pool against direct calls, the fit curves against the fit plus the averaging."""

import numpy as np
import pandas as pd

from loper_analysis.impedance.identification.fit import ImpedanceFit
from loper_analysis.impedance.identification.onset_fit import fit_curves, fit_null_pairs, mean_response_window
from loper_analysis.impedance.identification.window import N_SUBSTEPS
from loper_analysis.impedance.responses import ResponseSettings, null_pair_windows
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from tests.impedance.responses.twin_strides import DELAY, RATE, null_trial

#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20240613

PARAMS = segment_parameters_from_anthropometry(1.73, 64.9)


def _series(force_time_s=None):
    """A mean response with the onset at 0 s: the perturbed coordinates leave the unperturbed ones by
    (0, 0.1, -0.2, 0.05) tau^2 and the pelvis by 0.02 tau^2 (tau: time after the onset); constant forces."""
    t = np.round(np.arange(-30, 51) * 0.01, 12)
    tau2 = np.clip(t, 0.0, None) ** 2
    qu = np.column_stack([0.5 * t, 0.3 + 0.4 * t, 0.1 - 0.2 * t, 0.05 * np.sin(t)])
    qp = qu + tau2[:, None] * np.array([0.0, 0.1, -0.2, 0.05])
    pelvis = 0.01 * np.cos(t)
    tf = t if force_time_s is None else force_time_s
    return {
        "time_s": t,
        "q_unperturbed": qu,
        "q_perturbed": qp,
        "force_unperturbed_n": np.tile([1.0, 2.0], (len(tf), 1)),
        "force_perturbed_n": np.tile([3.0, -1.0], (len(tf), 1)),
        **({} if force_time_s is None else {"force_time_s": force_time_s}),
        "pelvis_angle_unperturbed_rad": pelvis,
        "pelvis_angle_perturbed_rad": pelvis + 0.02 * tau2,
    }


def test_mean_response_window_holds_the_analytic_deviation():
    """Window -0.1 .. 0.3 s about the onset at 0 s; measured hip, knee, ankle = (-0.08, -0.3, -0.25) tau^2,
    the pelvis deviation 0.02 tau^2 at the data samples, the perturbed force (3, -1) N throughout."""
    window = mean_response_window(_series(), PARAMS, {"window": ResponseWindow(before_s=0.1, after_s=0.3)})
    assert window.onset_s == 0.0
    np.testing.assert_allclose(window.time_s, np.arange(-10, 31) * 0.01, rtol=0, atol=1e-12)
    tau2 = np.clip(window.time_s, 0.0, None) ** 2
    np.testing.assert_allclose(window.measured, tau2[:, None] * [-0.08, -0.3, -0.25], rtol=0, atol=1e-14)
    at_samples = window.pelvis_deviation[:: 2 * N_SUBSTEPS, 0]
    np.testing.assert_allclose(at_samples, 0.02 * tau2, rtol=0, atol=1e-14)
    np.testing.assert_allclose(window.force_perturbed_n, np.broadcast_to([3.0, -1.0], window.force_perturbed_n.shape))


def test_mean_response_window_takes_forces_at_their_own_clock():
    """Forces sampled at 1000 Hz (``force_time_s`` in the series) give the same constant perturbed force."""
    own = mean_response_window(
        _series(np.arange(-300, 501) * 0.001), PARAMS, {"window": ResponseWindow(before_s=0.1, after_s=0.3)}
    )
    shared = mean_response_window(_series(), PARAMS, {"window": ResponseWindow(before_s=0.1, after_s=0.3)})
    np.testing.assert_allclose(own.force_perturbed_n, shared.force_perturbed_n, rtol=0, atol=1e-12)
    np.testing.assert_allclose(own.feedforward, shared.feedforward, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(own.measured, shared.measured)


def test_fit_null_pairs_pools_the_named_trials(rng):
    """Matched strides: a null trial named like a loaded input is the loaded one; no null trials: the inputs;
    the conditional counterfactual returns the series' own null pairs."""
    a, _ = null_trial(rng)
    b, _ = null_trial(rng)
    a.name, b.name = "walk-a", "walk-b"
    onset_ms = DELAY / RATE * 1e3
    matched = ResponseSettings(rate_hz=RATE, counterfactual="matched_stride")
    of_a = null_pair_windows([a.inputs()], onset_ms, matched, source="S01")
    of_b = null_pair_windows([b.inputs()], onset_ms, matched, source="S01")
    assert not np.array_equal(of_a["q_unperturbed"], of_b["q_unperturbed"])
    cases = {
        "named": ([a.inputs(), b.inputs()], [{"name": "walk-b"}], of_b),
        "empty": ([a.inputs()], [], of_a),
        "not loaded": ([a.inputs()], [b.inputs()], of_b),
    }
    for label, (inputs, null_trials, expected) in cases.items():
        out = fit_null_pairs(inputs, null_trials, {}, onset_ms, matched, None, "S01")
        assert out["n_pairs"] == expected["n_pairs"], label
        np.testing.assert_array_equal(out["q_unperturbed"], expected["q_unperturbed"], err_msg=label)
        np.testing.assert_array_equal(out["q_perturbed"], expected["q_perturbed"], err_msg=label)
    own = {"n_pairs": 3}
    conditional = ResponseSettings(rate_hz=RATE, counterfactual="conditional")
    assert fit_null_pairs([a.inputs()], [], {"null_pairs": own}, onset_ms, conditional, None, "S01") is own


def test_fit_curves_add_the_averaging_back(rng):
    """Measured and model columns are the fit's responses plus the averaging, joint by joint."""
    n = 5
    time_s = np.arange(n) * 0.01
    measured, model, averaging = rng.normal(size=(3, n, 3))
    six = np.zeros(6)
    fit = ImpedanceFit(
        estimate=six, cost=0.0, sum_sq_error_rad2=0.0, ci95_low=six, ci95_high=six, sd=six, ci_dof=1,
        correlation=np.eye(6), vaf_pct=np.zeros(3), success=True, message="", n_starts=1, n_starts_at_best=1,
        n_simulations=1, starts=six[None], start_estimates=six[None], start_costs=np.zeros(1),
        time_s=time_s, measured=measured, model=model,
    )  # fmt: skip
    curves = fit_curves(fit, averaging)
    assert list(curves.columns) == [
        "time_s",
        "hip_measured_rad",
        "knee_measured_rad",
        "ankle_measured_rad",
        "hip_model_rad",
        "knee_model_rad",
        "ankle_model_rad",
    ]
    expected = pd.DataFrame(
        {
            "time_s": time_s,
            **{f"{j}_measured_rad": measured[:, i] + averaging[:, i] for i, j in enumerate(["hip", "knee", "ankle"])},
            **{f"{j}_model_rad": model[:, i] + averaging[:, i] for i, j in enumerate(["hip", "knee", "ankle"])},
        }
    )
    pd.testing.assert_frame_equal(curves, expected, check_exact=True)
    np.testing.assert_allclose(curves.loc[2, "knee_model_rad"], model[2, 1] + averaging[2, 1], rtol=0, atol=0)
