"""Device-test trials of a synthetic subject: desired-force profiles and simulated robot logs.

Two trials per subject (the study's device tests), both with the free-hanging leg:

* ``device-frf``: broadband desired force (low-pass filtered Gaussian noise)
  for the frequency response;
* ``device-steps``: rectangular steps of 20, 40 and 60 N, 10 repetitions each,
  in a seeded random order.

The robot log also carries the sync signal that the motion-capture system
records: a 5 V pulse of ``sync_pulse_s`` every ``sync_period_s``.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
import pandas as pd
from scipy.signal import butter, sosfilt

from loper_analysis.checks import integer, positive
from loper_analysis.device.analysis import STEP_AMPLITUDES_N
from loper_analysis.device.controller import DeviceParameters, FreeLeg, simulate_device
from loper_analysis.errors import LoperInputError

__all__ = [
    "DeviceTestSettings",
    "DEVICE_TRIALS",
    "broadband_force",
    "step_force",
    "sync_signal",
    "simulate_device_trial",
]

DEVICE_TRIALS: tuple[str, ...] = ("device-frf", "device-steps")


@dataclass(frozen=True)
class DeviceTestSettings:
    """Desired-force profiles of the device tests (config key ``device.tests``, each field the key of its name).

    The broadband trial: ``broadband_duration_s`` (s) of Gaussian noise with SD ``broadband_sd_n`` (N) low-passed
    at ``broadband_bandwidth_hz`` (Hz); the step trial: each of ``step_amplitudes_n`` (N)
    ``step_repetitions`` times, ``step_on_s`` on after ``step_off_s`` off (s); both carry the sync output, a
    ``sync_level_v`` (V) pulse of ``sync_pulse_s`` every ``sync_period_s`` (s).

    Raises
    ------
    LoperInputError
        A value that is not positive (the repetitions: no integer >= 1; the amplitudes: none), naming its config
        key ``device.tests.<field>`` and the value.
    """

    broadband_duration_s: float = 120.0
    broadband_bandwidth_hz: float = 100.0
    broadband_sd_n: float = 15.0
    step_amplitudes_n: tuple[float, ...] = STEP_AMPLITUDES_N
    step_repetitions: int = 10
    step_on_s: float = 0.5
    step_off_s: float = 0.5
    sync_period_s: float = 1.0
    sync_pulse_s: float = 0.01
    sync_level_v: float = 5.0

    def __post_init__(self) -> None:
        for f in fields(self):
            key, value = f"device.tests.{f.name}", getattr(self, f.name)
            if f.name == "step_repetitions":
                integer(key, value, minimum=1)
            elif f.name == "step_amplitudes_n":
                if isinstance(value, str) or not isinstance(value, tuple) or not value:
                    raise LoperInputError(f"{key} must be a non-empty tuple of heights (N), got {value!r}")
                for a in value:
                    positive(key, a)
            else:
                positive(key, value)


def broadband_force(settings: DeviceTestSettings, sample_rate_hz: float, rng: np.random.Generator) -> np.ndarray:
    """Gaussian noise (SD ``broadband_sd_n`` before filtering) low-passed (4th-order Butterworth), N."""
    n = int(round(settings.broadband_duration_s * sample_rate_hz))
    if n < 10:
        raise LoperInputError(f"broadband_duration_s too short: {settings.broadband_duration_s} s")
    nyq = 0.5 * sample_rate_hz
    if not 0 < settings.broadband_bandwidth_hz < nyq:
        raise LoperInputError(
            f"broadband_bandwidth_hz must lie in 0 .. {nyq} Hz, got {settings.broadband_bandwidth_hz}"
        )
    sos = butter(4, settings.broadband_bandwidth_hz / nyq, output="sos")
    return sosfilt(sos, rng.normal(0.0, settings.broadband_sd_n, n))


def step_force(settings: DeviceTestSettings, sample_rate_hz: float, rng: np.random.Generator) -> np.ndarray:
    """Rectangular steps: every amplitude ``step_repetitions`` times, random order, N.

    Each step is ``step_off_s`` at zero, then ``step_on_s`` at the amplitude;
    the trial ends with one more off period.
    """
    if settings.step_repetitions < 1 or not settings.step_amplitudes_n:
        raise LoperInputError("device steps need >= 1 amplitude and >= 1 repetition")
    off = int(round(settings.step_off_s * sample_rate_hz))
    on = int(round(settings.step_on_s * sample_rate_hz))
    if off < 1 or on < 1:
        raise LoperInputError(
            f"step_on_s and step_off_s must each hold >= 1 sample, got {settings.step_on_s}, {settings.step_off_s}"
        )
    order = rng.permutation(np.repeat(np.asarray(settings.step_amplitudes_n, float), settings.step_repetitions))
    pieces = [np.concatenate([np.zeros(off), np.full(on, a)]) for a in order]
    return np.concatenate(pieces + [np.zeros(off)])


def sync_signal(n: int, settings: DeviceTestSettings, sample_rate_hz: float) -> np.ndarray:
    """The robot's sync output (V): a pulse of ``sync_pulse_s`` every ``sync_period_s`` from t = 0."""
    t = np.arange(n) / sample_rate_hz
    phase = np.mod(t + 0.5 / sample_rate_hz, settings.sync_period_s)
    return np.where(phase < settings.sync_pulse_s, settings.sync_level_v, 0.0)


def simulate_device_trial(
    trial: str,
    device: DeviceParameters,
    leg: FreeLeg,
    settings: DeviceTestSettings,
    seed: int | np.random.SeedSequence,
) -> pd.DataFrame:
    """A robot-log frame (columns of :mod:`loper_analysis.io.robot_log`) for one device-test trial."""
    if trial not in DEVICE_TRIALS:
        raise LoperInputError(f"unknown device trial '{trial}'; known: {', '.join(DEVICE_TRIALS)}")
    ss = np.random.SeedSequence(seed) if not isinstance(seed, np.random.SeedSequence) else seed
    profile_seed, noise_seed = ss.spawn(2)
    rng = np.random.default_rng(profile_seed)
    fs = device.sample_rate_hz
    fd = broadband_force(settings, fs, rng) if trial == "device-frf" else step_force(settings, fs, rng)
    sim = simulate_device(fd, device, leg, seed=noise_seed)
    return pd.DataFrame(
        {
            "time_s": sim["time_s"],
            "force_desired_n": sim["force_desired_n"],
            "force_measured_n": sim["force_measured_n"],
            "motor_angle_rad": sim["motor_angle_rad"],
            "motor_velocity_rad_s": sim["motor_velocity_rad_s"],
            "sync_v": sync_signal(len(fd), settings, fs),
            "perturbation": (np.abs(fd) > 0).astype(np.int64),
            "safety_state": sim["safety_state"].astype(np.int64),
        }
    )
