"""The identification window: prepare_window's checks, the model response and the prediction error."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.impedance.identification import (
    prediction_error,
    prepare_window,
    simulate_deviation,
    simulate_response,
)
from loper_analysis.impedance.responses.response_window import ResponseWindow
from tests.impedance.identification.validation_windows import (
    MID_TRUTH,
    PARAMS,
    SETTINGS,
    expect_error,
    mid_trial,
    truth_window,
    window_for,
)


@pytest.fixture(scope="module")
def trial_mid():
    return mid_trial()


# ---------------------------------------------------------------- model response


def test_response_is_exactly_zero_without_perturbation(trial_mid):
    """The deviation dynamics subtract q_ref'': no force, no initial deviation -> e = 0."""
    t, qu, _, _, pelvis, _ = trial_mid
    tf = trial_mid[5]
    window = window_for((t, qu, qu, np.zeros((len(tf), 2)), pelvis, tf))
    np.testing.assert_allclose(window.measured, 0.0, rtol=0, atol=0)
    P = np.array([[0.0, 0.0, 0.0, 0.0, 0.0, 0.0], [150.0, 4.0, 150.0, 4.0, 150.0, 4.0]])
    np.testing.assert_allclose(simulate_response(window, P), 0.0, rtol=0, atol=1e-15)


def test_prediction_error_vanishes_at_the_truth_with_the_truth_step(trial_mid):
    """Identification with the truth's own step and force reproduces the data (round trip); measured 2.4e-16 rad."""
    window = truth_window(trial_mid)
    assert np.abs(window.measured).max() > 0.05
    np.testing.assert_allclose(prediction_error(window, MID_TRUTH), 0.0, rtol=0, atol=1e-13)


def test_batch_and_single_response_agree_bitwise(trial_mid):
    window = truth_window(trial_mid)
    batch = simulate_response(window, np.stack([MID_TRUTH, MID_TRUTH + 1.0]))
    np.testing.assert_array_equal(batch[0], simulate_response(window, MID_TRUTH))


def test_simulate_deviation_is_the_perturbed_trial_deviation(trial_mid):
    """perturbed_trial adds simulate_deviation to q_u: with the truth's step and the same window start
    the deviation over the window is the data's q_p - q_u (round trip through the same kernel)."""
    t, qu, qp, *_ = trial_mid
    window = truth_window(trial_mid)
    deviation = simulate_deviation(window, MID_TRUTH[None])
    assert deviation.shape == (1, window.n_samples, 4)
    i0 = int(np.searchsorted(t, window.time_s[0] - 1e-9))
    np.testing.assert_allclose(deviation[0], (qp - qu)[i0 : i0 + window.n_samples], rtol=0, atol=1e-13)


# ---------------------------------------------------------------- input checks


def test_prepare_window_rejects_bad_input(trial_mid):
    t, qu, qp, fp, pelvis, tf = trial_mid
    kw = dict(
        force_perturbed_n=fp, force_time_s=tf, pelvis_angle_unperturbed_rad=pelvis, pelvis_angle_perturbed_rad=pelvis
    )
    onset = SETTINGS.onset_s

    bad = qu.copy()
    bad[7, 2] = np.nan
    expect_error(lambda: prepare_window(t, bad, qp, PARAMS, onset, **kw), "q_unperturbed", "row 7", "nan")
    bad = qp.copy()
    bad[11, 0] = np.inf
    expect_error(lambda: prepare_window(t, qu, bad, PARAMS, onset, **kw), "q_perturbed", "row 11", "inf")
    expect_error(lambda: prepare_window(t, qu[:, :3], qp, PARAMS, onset, **kw), "q_unperturbed", "(55, 3)")
    expect_error(lambda: prepare_window(t, qu, qp[:-1], PARAMS, onset, **kw), "q_perturbed", "54", "55")
    t_bad = t.copy()
    t_bad[10] += 0.002
    expect_error(lambda: prepare_window(t_bad, qu, qp, PARAMS, onset, **kw), "time_s", "uniform", "sample 9")
    expect_error(
        lambda: prepare_window(t, qu, qp, PARAMS, onset, window=ResponseWindow(after_s=1.0), **kw),
        "window",
        "longer than the data",
    )
    expect_error(
        lambda: prepare_window(t, qu, qp, PARAMS, onset, window=ResponseWindow(before_s=1.0), **kw),
        "window",
        "longer than the data",
    )
    expect_error(lambda: prepare_window(t, qu, qp, PARAMS, onset, n_substeps=2.5, **kw), "n_substeps", "2.5")
    expect_error(lambda: prepare_window(t, qu, qp, PARAMS, onset, n_substeps=0, **kw), "n_substeps", "0")


def test_simulate_response_rejects_non_finite_impedance(trial_mid):
    window = window_for(trial_mid)
    expect_error(lambda: simulate_response(window, [1.0, np.nan, 3.0, 4.0, 5.0, 6.0]), "impedance")


def test_simulate_response_rejects_wrong_length_naming_its_shape(trial_mid):
    window = window_for(trial_mid)
    expect_error(lambda: simulate_response(window, [1.0, 2.0, 3.0]), "impedance", "(3,)")
