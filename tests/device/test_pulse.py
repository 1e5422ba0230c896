"""The shape and the finding of a force pulse (device.pulse): the second-order step's rise time, overshoot and
impulse; the pulse's onset, plateau and end; and the pulses found in a hand-built force trace at the samples they
were put, of the sign and size they were given, with the runs too short or too long left out."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.device.pulse import find_force_pulses, pulse_force, second_order_parameters, step_response
from loper_analysis.errors import LoperInputError

FS = 1000.0


def _trace(n=10_000, baseline_n=2.0):
    """A level force of ``baseline_n`` with a 40 N pulse at samples 2000-2099, a -30 N pulse at 4000-4049, a 10 ms
    blip of 40 N at 5000-5009 and a 0.6 s plateau of 40 N at 7000-7599."""
    f = np.full(n, baseline_n)
    f[2000:2100] += 40.0
    f[4000:4050] -= 30.0
    f[5000:5010] += 40.0
    f[7000:7600] += 40.0
    return f


def test_pulse_has_the_study_rise_time_overshoot_and_impulse():
    """Second-order step response: 10 ms (10-90 %), 30.5 % overshoot; a 40 N, 100 ms pulse carries 4 N·s."""
    zeta, wn = second_order_parameters(0.010, 30.5)
    assert zeta == pytest.approx(-np.log(0.305) / np.sqrt(np.pi**2 + np.log(0.305) ** 2), rel=1e-12)
    t = np.arange(0.0, 0.1, 1e-6)
    y = step_response(t, 0.010, 30.5)
    rising = t < np.pi / (wn * np.sqrt(1 - zeta**2))  # up to the peak
    rise = np.interp(0.9, y[rising], t[rising]) - np.interp(0.1, y[rising], t[rising])
    assert rise == pytest.approx(0.010, abs=2e-6)
    assert y.max() == pytest.approx(1.305, abs=1e-6)
    tt = np.arange(-0.05, 0.6, 1e-6)
    f = pulse_force(tt, 0.0, 0.1, 40.0, 0.010, 30.5)
    assert np.all(f[tt <= 0] == 0.0)
    assert np.trapezoid(f, tt) == pytest.approx(4.0, abs=1e-6)


def test_natural_frequency_scales_inversely_with_the_rise_time():
    """The damping ratio depends on the overshoot alone; twice the rise time halves the natural frequency."""
    zeta10, wn10 = second_order_parameters(0.010, 30.5)
    zeta20, wn20 = second_order_parameters(0.020, 30.5)
    assert zeta20 == zeta10 and wn20 == pytest.approx(wn10 / 2, rel=1e-12)
    # the peak of the step, 1 + overshoot, falls at pi / (wn * sqrt(1 - zeta^2))
    t_peak = np.pi / (wn20 * np.sqrt(1 - zeta20**2))
    assert step_response([t_peak], 0.020, 30.5)[0] == pytest.approx(1.305, abs=1e-12)


def test_a_long_pulse_settles_on_its_force_and_ends_at_zero():
    """A 40 N pulse from 0.2 s for 0.3 s: 0 before the onset; on its plateau and after its end within the
    second-order envelope exp(-zeta wn t) / sqrt(1 - zeta^2) of 40 N and 0; a negative force mirrors it."""
    zeta, wn = second_order_parameters(0.010, 30.5)
    t = np.arange(0.0, 1.0, 1e-3)
    f = pulse_force(t, 0.2, 0.3, 40.0, 0.010, 30.5)
    assert np.all(f[t <= 0.2] == 0.0)
    plateau, after = (t > 0.3) & (t < 0.5), t > 0.6
    envelope = 40.0 * np.exp(-zeta * wn * (t - 0.2)) / np.sqrt(1 - zeta**2)
    assert np.all(np.abs(f[plateau] - 40.0) <= envelope[plateau])
    assert np.all(np.abs(f[after]) <= 2 * 40.0 * np.exp(-zeta * wn * (t[after] - 0.5)) / np.sqrt(1 - zeta**2))
    assert np.max(np.abs(f[(t > 0.4) & (t < 0.5)] - 40.0)) < 0.01 and np.max(np.abs(f[t > 0.7])) < 0.01
    np.testing.assert_array_equal(pulse_force(t, 0.2, 0.3, -40.0, 0.010, 30.5), -f)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: second_order_parameters(0.0, 30.5), r"^rise_time_s must be a positive number, got 0.0$"),
        (lambda: second_order_parameters(0.01, 100.0), r"^overshoot_pct must lie in 0 .. 100 % \(exclusive\), got 100"),
        (lambda: second_order_parameters(0.01, 0.0), r"^overshoot_pct must lie in 0 .. 100 % \(exclusive\), got 0"),
        (lambda: pulse_force([0.0, 0.1], 0.0, -0.1, 40.0, 0.01, 30.5), r"^duration_s must be a positive number"),
    ],
)
def test_a_bad_shape_is_refused_by_name(call, message):
    with pytest.raises(LoperInputError, match=message):
        call()


def test_pulses_are_found_at_their_samples_with_their_signed_size():
    """A level force: the 40 N and -30 N pulses, first sample and one past the last, peak 40 and -30 above the
    level; the 10 ms blip (under 20 ms) and the 0.6 s plateau (over 0.5 s) are no pulses."""
    found = find_force_pulses(_trace(), FS)
    np.testing.assert_array_equal(found, [[2000, 2100, 40.0], [4000, 4050, -30.0]])
    assert find_force_pulses(_trace(), FS, min_duration_s=0.005)[:, 0].tolist() == [2000, 4000, 5000]


def test_pulses_stand_out_of_noise_and_a_nan_splits_one(rng):
    """Gaussian noise of SD 0.5 N on the level: the same two pulses (threshold 15 N); a NaN inside the first
    splits it into two runs of 50 and 49 samples; a 35 N threshold leaves out the -30 N pulse."""
    f = _trace() + rng.normal(0.0, 0.5, 10_000)
    found = find_force_pulses(f, FS)
    np.testing.assert_array_equal(found[:, :2], [[2000, 2100], [4000, 4050]])
    np.testing.assert_allclose(found[:, 2], [40.0, -30.0], atol=2.5)  # the largest of 100 draws: < 5 SD
    f[2050] = np.nan
    assert find_force_pulses(f, FS)[:, :2].tolist() == [[2000, 2050], [2051, 2100], [4000, 4050]]
    assert find_force_pulses(_trace(), FS, threshold_n=35.0)[:, :2].tolist() == [[2000, 2100]]
    assert find_force_pulses(_trace(), FS, threshold_n=50.0).shape == (0, 3)


def test_force_pulses_of_the_simulated_robot():
    """find_force_pulses: every 40 N pulse of the perturbation trial, none in minimal-impedance mode (the
    robot's start-up transient rings shorter than a pulse)."""
    from loper_analysis.device.controller import DeviceParameters, simulate_device
    from loper_analysis.synthetic.response import pulse_train

    fs = 1000.0
    t = np.arange(int(20 * fs)) / fs
    brace = 0.03 * np.sin(2 * np.pi * 0.9 * t)  # a thigh swinging at a stride frequency
    onsets = np.array([3.2, 7.55, 11.0, 15.31])
    fd = pulse_train(t, onsets, 40.0, 0.1)
    pulsed = simulate_device(fd, DeviceParameters(), None, brace_position_m=brace, seed=3)["force_measured_n"]
    free = simulate_device(0 * t, DeviceParameters(), None, brace_position_m=brace, seed=3)["force_measured_n"]
    found = find_force_pulses(pulsed.to_numpy(), fs)
    assert found.shape == (4, 3)
    assert np.all((t[found[:, 0].astype(int)] - onsets >= 0) & (t[found[:, 0].astype(int)] - onsets < 0.03))
    assert np.all((found[:, 2] > 35.0) & (found[:, 2] < 60.0))
    assert find_force_pulses(free.to_numpy(), fs).shape == (0, 3)


def test_a_force_of_under_two_finite_samples_has_no_pulse_and_bad_arguments_are_named():
    assert find_force_pulses(np.array([np.nan, 40.0, np.nan]), FS).shape == (0, 3)
    with pytest.raises(LoperInputError) as err:
        find_force_pulses(_trace(), FS, min_duration_s=0.5, max_duration_s=0.2, source="walk01 load cell")
    assert str(err.value) == "walk01 load cell: max_duration_s (0.2) must exceed min_duration_s (0.5)"
    with pytest.raises(LoperInputError, match=r"^force: the force must be 1-D, got shape \(2, 5000\)$"):
        find_force_pulses(_trace().reshape(2, 5000), FS)
    with pytest.raises(LoperInputError, match=r"^force: sample_rate_hz must be a positive number, got -1000.0$"):
        find_force_pulses(_trace(), -1000.0)
