"""Device analysis on signals with known answers, the summary beside the study, and the simulated device against the
study."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.signal import cont2discrete, dlsim, freqz

from loper_analysis.device.analysis import (
    FRFSettings,
    StepSettings,
    average_step,
    bandwidth_hz,
    device_summary,
    frequency_response,
    step_averages,
    step_metrics,
    step_onsets,
    step_table,
)
from loper_analysis.device.controller import DeviceParameters, FreeLeg, simulate_device
from loper_analysis.device.trials import DeviceTestSettings, simulate_device_trial
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from tests.study_files import device_config

FS = 1000.0


def _second_order(wn: float, zeta: float, gain: float = 1.0):
    """Discrete (bilinear) 2nd-order low-pass at 1 kHz: (b, a)."""
    b, a, _ = cont2discrete(([gain * wn**2], [1, 2 * zeta * wn, wn**2]), 1 / FS, method="bilinear")
    return np.ravel(b), np.ravel(a)


def _analytic_bandwidth(b, a, ref_gain):
    f = np.linspace(1, 200, 200_000)
    _, h = freqz(b, a, worN=f, fs=FS)
    i = np.argmax(np.abs(h) < ref_gain / np.sqrt(2))
    return f[i]


@pytest.mark.parametrize("gain", [1.0, 0.9])
def test_frf_and_bandwidth_of_a_known_second_order_system(gain):
    b, a = _second_order(2 * np.pi * 30, 0.4, gain)
    x = np.random.default_rng(0).normal(0, 10, 120_000)
    _, y = dlsim((b, a, 1 / FS), x)
    frf = frequency_response(x, y[:, 0], FS)
    _, h = freqz(b, a, worN=frf.frequency_hz.to_numpy(), fs=FS)
    band = frf.frequency_hz < 100
    np.testing.assert_allclose(frf.gain[band], np.abs(h[band]), rtol=0.02)
    np.testing.assert_allclose(frf.phase_deg[band], np.degrees(np.unwrap(np.angle(h[band]))), atol=1.5)
    assert frf.coherence[band].min() > 0.999
    bw = bandwidth_hz(frf.frequency_hz, frf.gain)
    expected = _analytic_bandwidth(b, a, gain)
    assert abs(bw - expected) / expected < 0.02, (bw, expected)


def test_step_metrics_of_a_known_second_order_step():
    zeta, wn = 0.36, 2 * np.pi * 19.7
    wd = wn * np.sqrt(1 - zeta**2)

    def response(t):
        t = np.clip(t, 0, None)
        return 0.9 * (1 - np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / np.sqrt(1 - zeta**2) * np.sin(wd * t)))

    fine = np.linspace(0, 0.2, 2_000_001)
    yf = response(fine)
    rise = 1e3 * (fine[np.argmax(yf >= 0.9 * 0.9)] - fine[np.argmax(yf >= 0.1 * 0.9)])
    overshoot = 100 * np.exp(-np.pi * zeta / np.sqrt(1 - zeta**2))
    # ten repetitions of three amplitudes, 1 kHz, small noise
    rng = np.random.default_rng(1)
    fd, fm = [], []
    for amp in rng.permutation(np.repeat([20.0, 40.0, 60.0], 10)):
        t = np.arange(-500, 500) / FS
        fd.append(np.where(t >= 0, amp, 0.0))
        fm.append(amp * response(t) + rng.normal(0, 0.05, t.size))
    fd, fm = np.concatenate(fd), np.concatenate(fm)
    tab = step_table(step_averages(fd, fm, FS, after_s=0.45), steady_window_s=(0.3, 0.45))
    assert list(tab.amplitude_n) == [20.0, 40.0, 60.0] and (tab.n_repetitions == 10).all()
    np.testing.assert_allclose(tab.rise_time_ms, rise, rtol=0.02)
    np.testing.assert_allclose(tab.overshoot_pct, overshoot, rtol=0.02)
    np.testing.assert_allclose(tab.steady_state_n, 0.9 * tab.amplitude_n, rtol=0.01)


def test_bad_inputs_are_named():
    x = np.zeros(6000)
    x[1234] = np.nan
    with pytest.raises(LoperInputError, match="desired_n is not finite at sample 1234"):
        frequency_response(x, np.zeros(6000), FS)
    with pytest.raises(LoperInputError, match="desired_n needs >= 5000 samples, got 100"):
        frequency_response(np.ones(100), np.ones(100), FS, window_samples=5000)
    with pytest.raises(LoperInputError, match="no step found"):
        step_onsets(np.zeros(1000), FS)
    fd = np.zeros(3000)
    fd[1000:1500] = 30.0  # 50 % from 20 N, 25 % from 40 N
    with pytest.raises(LoperInputError, match="sample 1000 has height 30"):
        step_averages(fd, fd, FS)
    with pytest.raises(LoperInputError, match="step at sample 2990"):
        average_step(np.zeros(3000), np.zeros(3000), FS, [2990])
    with pytest.raises(LoperInputError, match="never drops"):
        bandwidth_hz(np.linspace(0.1, 100, 500), np.ones(500))
    with pytest.raises(LoperInputError, match="not a rising step"):
        t = np.linspace(-0.05, 0.3, 351)
        step_metrics(t, np.where(t > 0, -5.0, 0.0), 40.0)


def test_device_summary_of_known_tables():
    """A gain falling linearly in log-frequency from 0 dB at 10 Hz to -6 dB at 40 Hz crosses -3 dB at 20 Hz."""
    f = np.geomspace(0.25, 100.0, 161)
    db = np.where(f <= 10.0, 0.0, -6.0 * np.log(f / 10.0) / np.log(4.0))
    frf = pd.DataFrame({"frequency_hz": f, "gain": 10 ** (db / 20), "phase_deg": 0.0, "coherence": 1.0})
    steps = pd.DataFrame(
        {
            "amplitude_n": [20.0, 40.0, 60.0],
            "n_repetitions": 10,
            "rise_time_ms": [9.0, 10.0, 14.0],
            "overshoot_pct": [30.0, 33.0, 36.0],
            "steady_state_n": [18.0, 36.9, 54.0],
            "peak_n": [23.4, 49.1, 73.4],
        }
    )
    summary = device_summary(frf, steps, (0.5, 2.0))
    s = summary.set_index("metric")
    assert list(summary.columns) == ["metric", "value", "study_value", "unit", "difference_pct"]
    expected = {
        "bandwidth_hz": (20.0, 39.0),
        "rise_time_ms": (11.0, 10.0),
        "overshoot_pct": (33.0, 30.5),
        "steady_state_40n_n": (36.9, 36.0),
    }
    for metric, (value, study) in expected.items():
        np.testing.assert_allclose(s.loc[metric, "value"], value, rtol=1e-9, err_msg=metric)
        assert s.loc[metric, "study_value"] == study
        np.testing.assert_allclose(s.loc[metric, "difference_pct"], 100 * (value - study) / study, rtol=1e-9)
    np.testing.assert_allclose(s.loc["rise_time_ms_at_60n", "value"], 14.0)
    np.testing.assert_allclose(s.loc["steady_state_n_at_20n", "value"], 18.0)


def test_simulated_device_reproduces_the_study_within_15_percent():
    dev, leg, tests = DeviceParameters(), FreeLeg(), DeviceTestSettings()
    frf_log = simulate_device_trial("device-frf", dev, leg, tests, 11)
    frf = frequency_response(frf_log.force_desired_n, frf_log.force_measured_n, FS)
    bw = bandwidth_hz(frf.frequency_hz, frf.gain)
    steps = simulate_device_trial("device-steps", dev, leg, tests, 12)
    tab = step_table(
        step_averages(steps.force_desired_n, steps.force_measured_n, FS, after_s=0.45), steady_window_s=(0.15, 0.3)
    )
    at40 = tab.set_index("amplitude_n").loc[40.0]
    for value, study in (
        (bw, 39.0),
        (tab.rise_time_ms.mean(), 10.0),
        (tab.overshoot_pct.mean(), 30.5),
        (at40.steady_state_n, 36.0),
    ):
        assert abs(value - study) / study <= 0.15, (value, study)
    # minimal-impedance walking: prescribed brace motion of a +-0.3 rad hip swing, 36 strides/min
    t = np.arange(0, 30, 1 / FS)
    period = 60 / 36
    hip = 0.08 + 0.30 * np.cos(2 * np.pi * t / period) + 0.06 * np.cos(4 * np.pi * t / period + 0.8)
    walk = simulate_device(np.zeros_like(t), dev, None, brace_position_m=0.34 * np.sin(hip), seed=5)
    f = walk.force_measured_n.to_numpy()[5000:]
    rms, peak = np.sqrt(np.mean(f**2)), np.abs(f).max()
    assert abs(rms - 2.05) / 2.05 <= 0.15, rms  # study 1.97 (stance) / 2.13 (swing)
    assert abs(peak - 4.55) / 4.55 <= 0.15, peak  # study 4.46 / 4.63


# --------------------------------------------------------------------------- settings from the config

#: A ``device.analysis`` section unlike the shipped one in every key.
ANALYSIS = {
    "welch_window_samples": 4000,
    "welch_overlap_samples": 100,
    "bandwidth_reference_band_hz": [0.4, 1.5],
    "step_before_s": 0.04,
    "step_after_s": 0.5,
    "steady_window_s": [0.2, 0.35],
}


def test_analysis_settings_from_config_hold_every_key():
    settings = stage_settings(device_config(analysis=ANALYSIS), "device").analysis
    assert settings.frf == FRFSettings(window_samples=4000, overlap_samples=100)
    assert settings.steps == StepSettings(before_s=0.04, after_s=0.5, steady_window_s=(0.2, 0.35))
    assert settings.reference_band_hz == (0.4, 1.5)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("welch_window_samples", 8, "device.analysis.welch_window_samples must be an integer >= 16, got 8"),
        (
            "welch_overlap_samples",
            4000,
            "device.analysis.welch_overlap_samples must be below device.analysis.welch_window_samples (4000), got 4000",
        ),
        ("step_after_s", 0.0, "device.analysis.step_after_s must be a positive number, got 0.0"),
        (
            "steady_window_s",
            [0.3, 0.2],
            "device.analysis.steady_window_s must be [low, high] with low < high, got [0.3, 0.2]",
        ),
        (
            "bandwidth_reference_band_hz",
            [0.5],
            "device.analysis.bandwidth_reference_band_hz must be two numbers [low, high], got (0.5,)",
        ),
    ],
)
def test_a_bad_analysis_value_is_refused_naming_its_key(key, value, message):
    with pytest.raises(LoperInputError) as info:
        _ = stage_settings(device_config(analysis={**ANALYSIS, key: value}), "device").analysis
    assert str(info.value) == message
