"""Device-test trials: desired-force profiles, sync pulses and simulated robot-log frames."""

import dataclasses

import numpy as np
import pytest
from scipy.signal import butter, sosfreqz, welch

from loper_analysis.device.controller import DeviceParameters, FreeLeg
from loper_analysis.device.trials import (
    DeviceTestSettings,
    broadband_force,
    simulate_device_trial,
    step_force,
    sync_signal,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from tests.study_files import device_config

FS = 1000.0


def test_step_profile_has_every_amplitude_ten_times():
    s = DeviceTestSettings()
    fd = step_force(s, FS, np.random.default_rng(0))
    assert len(fd) == 30 * 1000 + 500
    rises = np.flatnonzero(np.diff(fd) > 0) + 1
    heights = fd[rises]
    for a in (20.0, 40.0, 60.0):
        assert np.sum(heights == a) == 10
    assert np.all(np.diff(rises) == 1000)
    # each step lasts step_on_s
    falls = np.flatnonzero(np.diff(fd) < 0) + 1
    np.testing.assert_array_equal(falls - rises, 500)


def test_broadband_force_spectrum_is_flat_then_falls():
    s = DeviceTestSettings(broadband_duration_s=60.0)
    fd = broadband_force(s, FS, np.random.default_rng(1))
    f, p = welch(fd, FS, nperseg=4000)
    flat = p[(f > 2) & (f < 50)]
    # one-sided PSD of white noise of variance sd^2 in the pass band: 2 sd^2 / fs
    # (the band mean of a 60 s Welch estimate scatters by about 3 %: 4 sigma)
    np.testing.assert_allclose(flat.mean(), 2 * s.broadband_sd_n**2 / FS, rtol=0.12)
    # the digital 4th-order Butterworth: -3 dB at 100 Hz, -28 dB at 200 Hz (bilinear warping)
    ref = flat.mean()
    sos = butter(4, 100 / (FS / 2), output="sos")
    for fq in (100.0, 150.0, 200.0):
        _, h = sosfreqz(sos, worN=[fq], fs=FS)
        expected_db = 20 * np.log10(abs(h[0]))
        band = (f > fq - 5) & (f < fq + 5)
        np.testing.assert_allclose(10 * np.log10(p[band].mean() / ref), expected_db, atol=1.0)


def test_sync_pulses():
    s = DeviceTestSettings()
    v = sync_signal(5000, s, FS)
    edges = np.flatnonzero(np.diff(np.r_[0.0, v]) > 0)
    np.testing.assert_array_equal(edges, [0, 1000, 2000, 3000, 4000])
    assert v.sum() == 5 * 10 * 5.0


def test_trial_frame_and_determinism():
    s = DeviceTestSettings(step_repetitions=1, broadband_duration_s=5.0)
    a = simulate_device_trial("device-steps", DeviceParameters(), FreeLeg(), s, 7)
    b = simulate_device_trial("device-steps", DeviceParameters(), FreeLeg(), s, 7)
    assert a.equals(b)
    assert list(a.columns) == [
        "time_s",
        "force_desired_n",
        "force_measured_n",
        "motor_angle_rad",
        "motor_velocity_rad_s",
        "sync_v",
        "perturbation",
        "safety_state",
    ]
    assert len(a) == 3500
    np.testing.assert_array_equal(a.perturbation, (a.force_desired_n != 0).astype(int))


def test_unknown_trial_is_refused_by_name():
    s = DeviceTestSettings(step_repetitions=1, broadband_duration_s=5.0)
    with pytest.raises(LoperInputError, match="device-walk"):
        simulate_device_trial("device-walk", DeviceParameters(), FreeLeg(), s, 7)


# --------------------------------------------------------------------------- settings from the config

#: A ``device.tests`` section unlike the shipped one in every key.
TESTS = {
    "broadband_duration_s": 60.0,
    "broadband_bandwidth_hz": 80.0,
    "broadband_sd_n": 12.0,
    "step_amplitudes_n": [10.0, 30.0],
    "step_repetitions": 4,
    "step_on_s": 0.4,
    "step_off_s": 0.6,
    "sync_period_s": 2.0,
    "sync_pulse_s": 0.02,
    "sync_level_v": 3.3,
}


def test_device_test_settings_from_config_hold_every_key():
    settings = stage_settings(device_config(tests=TESTS), "device").tests
    assert dataclasses.asdict(settings) == {**TESTS, "step_amplitudes_n": (10.0, 30.0)}


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("step_repetitions", 0, "device.tests.step_repetitions must be an integer >= 1, got 0"),
        ("broadband_sd_n", -1.0, "device.tests.broadband_sd_n must be a positive number, got -1.0"),
        ("step_amplitudes_n", [], "device.tests.step_amplitudes_n must be a non-empty tuple of heights (N), got ()"),
        ("step_amplitudes_n", [20.0, 0.0], "device.tests.step_amplitudes_n must be a positive number, got 0.0"),
    ],
)
def test_a_bad_device_test_value_is_refused_naming_its_key(key, value, message):
    with pytest.raises(LoperInputError) as info:
        _ = stage_settings(device_config(tests={**TESTS, key: value}), "device").tests
    assert str(info.value) == message
