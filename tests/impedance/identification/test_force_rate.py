"""The force at its own rate: stage forces, impulse, coverage, and identification from 1 kHz against 128 Hz."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from loper_analysis.device.pulse import pulse_force
from loper_analysis.impedance.identification import (
    identify_impedance,
    per_step,
    prepare_window,
    stage_force_means,
    step_stage_forces,
)
from loper_analysis.impedance.identification.validation import validation_pulse
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS, expect_error, mid_trial, window_for


def _impulse(window) -> np.ndarray:
    """The impulse (N·s, x/y) RK4 gives the perturbed leg: sum over steps of h/6 (F1 + 2 F2 + 2 F3 + F4)."""
    f = window.force_perturbed_n
    return window.step_s / 6 * (f[:, 0] + 2 * f[:, 1] + 2 * f[:, 2] + f[:, 3]).sum(axis=0)


def test_rectangle_impulse_4_00_at_1_khz_against_3_75_at_128_hz():
    """An ideal 40 N, 100 ms rectangle switched on right after the onset sample: its 128 Hz samples,
    joined by straight lines, carry 12 x 7.8125 ms x 40 N = 3.75 N·s; its 1 kHz samples give the
    stages the whole 4.00 N·s."""
    t, qu, _, _, pelvis, tf = mid_trial()
    on = lambda x: (x > SETTINGS.onset_s + 1e-12) & (x <= SETTINGS.onset_s + 0.1 + 1e-12)  # noqa: E731
    f128 = np.where(on(t)[:, None], [40.0, 0.0], 0.0)
    f1k = np.where(on(tf)[:, None], [40.0, 0.0], 0.0)
    kw = dict(pelvis_angle_unperturbed_rad=pelvis, pelvis_angle_perturbed_rad=pelvis)
    w128 = prepare_window(t, qu, qu, PARAMS, SETTINGS.onset_s, force_perturbed_n=f128, **kw)
    w1k = prepare_window(t, qu, qu, PARAMS, SETTINGS.onset_s, force_perturbed_n=f1k, force_time_s=tf, **kw)
    np.testing.assert_allclose(_impulse(w128), [3.75, 0.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(_impulse(w1k), [4.00, 0.0], rtol=0, atol=1e-9)


@pytest.mark.parametrize(("natural_hz", "matched_bound", "plain_over_matched"), [(0.0, 1e-11, 1e6), (3.0, 1e-6, 30.0)])
def test_step_stage_forces_give_rk4_the_exact_forced_response(natural_hz, matched_bound, plain_over_matched):
    """Peer engine: y' = A y + b F(t), a free mass (0 Hz) or a damped 3 Hz oscillator (the swing leg's range),
    driven by the study's pulse sampled at 1 kHz. RK4 with 3.9 ms steps and the stage forces of
    step_stage_forces against SciPy's DOP853 (rtol 1e-13) on the cubic spline of the same samples, relative to
    the peak response. Free mass: exact (RK4's series ends at A, measured 4.4e-14) against 5.1e-5 with the
    force at the stage times; 3 Hz: 4.0e-7 against 3.4e-5."""
    from scipy.interpolate import CubicSpline

    wn, zeta = 2 * np.pi * natural_hz, 0.3
    A = np.array([[0.0, 1.0], [-(wn**2), -2 * zeta * wn]])
    b = np.array([0.0, 1.0])
    tf = np.arange(0.0, 0.4 + 1e-9, 1e-3)
    f = pulse_force(tf, 0.05, 0.1, 40.0, 0.010, 30.5)
    spline = CubicSpline(tf, f)
    h, n_steps = 1 / 256, 89
    exact = solve_ivp(
        lambda t, y: A @ y + b * spline(t),
        (0.0, h * n_steps),
        [0.0, 0.0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-16,
        max_step=2e-4,
        t_eval=h * np.arange(n_steps + 1),
    ).y.T

    def rk4(stage_f):
        y, out = np.zeros(2), [np.zeros(2)]
        for k in range(n_steps):
            f1, f2, f3, f4 = stage_f[k]
            k1 = A @ y + b * f1
            k2 = A @ (y + h / 2 * k1) + b * f2
            k3 = A @ (y + h / 2 * k2) + b * f3
            k4 = A @ (y + h * k3) + b * f4
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            out.append(y)
        return np.array(out)

    matched = step_stage_forces(tf, np.stack([f, 0 * f], axis=-1), 0.0, h, n_steps)[:, :, 0]
    stages = h / 2 * np.arange(2 * n_steps + 1)
    plain = per_step(np.stack([spline(stages), 0 * stages], axis=-1))[:, :, 0]
    peak = np.abs(exact[:, 0]).max()
    err_matched = np.abs(rk4(matched)[:, 0] - exact[:, 0]).max()
    err_plain = np.abs(rk4(plain)[:, 0] - exact[:, 0]).max()
    assert err_matched < matched_bound * peak
    assert err_plain > plain_over_matched * err_matched
    assert err_plain > 1e-5 * peak


def test_stage_forces_of_a_constant_force_are_that_force():
    tf = np.arange(0.0, 0.2, 1e-3)
    f = np.tile([3.0, -2.0], (tf.size, 1))
    np.testing.assert_allclose(
        step_stage_forces(tf, f, 0.01, 1 / 256, 40), np.broadcast_to([3.0, -2.0], (40, 4, 2)), rtol=0, atol=1e-12
    )
    stages = 0.01 + 1 / 512 * np.arange(81)
    np.testing.assert_allclose(stage_force_means(tf, f, stages), np.broadcast_to([3.0, -2.0], (81, 2)), atol=1e-12)


def test_force_that_does_not_cover_the_window_is_refused():
    t, qu, qp, fp, pelvis, tf = mid_trial()
    short = tf < SETTINGS.onset_s + 0.2
    expect_error(
        lambda: prepare_window(
            t, qu, qp, PARAMS, SETTINGS.onset_s, force_perturbed_n=fp[short], force_time_s=tf[short]
        ),
        "force at its own rate",
        f"{tf[0]:.4f} .. {tf[short][-1]:.4f} s",
        "does not cover the fit window",
        "0.0266 .. 0.3000 s",
    )
    expect_error(
        lambda: prepare_window(t, qu, qp, PARAMS, SETTINGS.onset_s, force_perturbed_n=fp[:-1], force_time_s=tf),
        "force_perturbed_n",
        "like force_time_s",
    )
    bad = tf.copy()
    bad[5] = bad[4]
    expect_error(
        lambda: prepare_window(t, qu, qp, PARAMS, SETTINGS.onset_s, force_perturbed_n=fp, force_time_s=bad),
        "force_time_s",
        "strictly increasing",
        "sample 4",
    )


@pytest.mark.parametrize("truth", [[75.0, 2.0, 75.0, 2.0, 75.0, 2.0], [150.0, 4.0, 150.0, 4.0, 0.0, 0.0]])
def test_identification_from_1_khz_force_beats_128_hz_samples(truth):
    """Known answer: the truth is plain RK4 with 32 steps per 128 Hz sample and the study's pulse at every stage.
    The identification with 2 steps per sample recovers hip and knee K within 0.005 N·m/rad and D within
    0.0005 N·m·s/rad from the pulse's 1 kHz samples (measured: <= 0.0002 and <= 0.00001); from its 128 Hz
    samples, joined by straight lines, the largest hip/knee error is more than 20 times that (measured:
    0.016 / 0.0065 at the middle truth, 0.13 / 0.017 at the stiff one)."""
    from loper_analysis.impedance.identification.validation import perturbed_trial

    truth = np.asarray(truth)
    trial = perturbed_trial(PARAMS, truth, SETTINGS)
    fits = {}
    for rate, overrides in (
        ("1k", {}),
        ("128", dict(force_time_s=None, force_perturbed_n=validation_pulse(trial[0], SETTINGS))),
    ):
        w = window_for(trial, **overrides)
        fits[rate] = (
            identify_impedance(
                w, n_starts=10, seed=0, lower=SETTINGS.lower, upper=SETTINGS.upper, tolerance=SETTINGS.tolerance
            ).estimate
            - truth
        )
    k, d = [0, 2], [1, 3]  # hip and knee
    assert np.abs(fits["1k"][k]).max() < 0.005
    assert np.abs(fits["1k"][d]).max() < 0.0005
    assert np.abs(fits["128"][k]).max() > 20 * np.abs(fits["1k"][k]).max()
    assert max(np.abs(fits["128"][k]).max() / 0.005, np.abs(fits["128"][d]).max() / 0.0005) > 1.0
