"""The simulated LOPER force controller: safety-layer behaviours, each driven into on purpose."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.device.controller import (
    SAFETY_LIMITED,
    SAFETY_MOTOR_OFF_POSITION,
    SAFETY_MOTOR_OFF_TORQUE,
    SAFETY_MOTOR_OFF_VELOCITY,
    SAFETY_OK,
    SAFETY_SERVO_OFF_POSITION,
    DeviceParameters,
    FreeLeg,
    safety_events,
    simulate_device,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.settings import stage_settings
from tests.study_files import device_config

DEV = DeviceParameters()
QUIET = DeviceParameters(loadcell_noise_sd_n=0.0, loadcell_resolution_n=0.0)
SOFT_LEG = FreeLeg(mass_kg=2.0, damping_ns_per_m=1.0, stiffness_n_per_m=1.0)  # hardly resists: the motor runs


def test_minimal_impedance_free_leg_stays_at_rest():
    log = simulate_device(np.zeros(2000), QUIET)
    np.testing.assert_allclose(log.force_measured_n, 0.0, atol=1e-12)
    np.testing.assert_allclose(log.motor_angle_rad, 0.0, atol=1e-12)
    assert (log.safety_state == SAFETY_OK).all()


def test_velocity_and_acceleration_limits():
    fd = np.zeros(400)  # stops before the position bound comes into play
    fd[100:] = 60.0
    log = simulate_device(fd, QUIET, SOFT_LEG)
    v = log.velocity_command_rad_s.to_numpy()
    assert np.abs(v).max() <= DEV.velocity_limit_rad_s + 1e-12
    assert np.abs(np.diff(v)).max() <= DEV.acceleration_limit_rad_s2 / DEV.sample_rate_hz + 1e-9
    assert (log.safety_state == SAFETY_LIMITED).sum() > 10
    # the command reached the velocity limit
    np.testing.assert_allclose(np.abs(v).max(), DEV.velocity_limit_rad_s, rtol=1e-12)


def test_position_bound_decelerates_and_holds():
    damped_leg = FreeLeg(mass_kg=2.0, damping_ns_per_m=60.0, stiffness_n_per_m=1.0)  # yields at ~1 m/s
    fd = np.zeros(3000)
    fd[100:] = 60.0
    log = simulate_device(fd, QUIET, damped_leg)
    th = log.motor_angle_rad.to_numpy()
    v = log.velocity_command_rad_s.to_numpy()
    assert th.max() < DEV.motor_cutoff_position_rad  # stopped before any cut-off
    assert th.max() > DEV.position_bound_rad - 0.05  # but it did reach the bound
    # the command never exceeds the constant-deceleration profile towards the bound
    room = np.clip(DEV.position_bound_rad - th, 0, None)
    allowed = np.sqrt(2 * DEV.acceleration_limit_rad_s2 * room)
    assert np.all(v <= allowed + 1e-9)
    assert th.max() <= DEV.position_bound_rad + 0.02  # servo lag overshoot only
    assert set(np.unique(log.safety_state)) <= {SAFETY_OK, SAFETY_LIMITED}


def test_no_outward_motion_beyond_the_bound():
    log = simulate_device(np.full(500, 40.0), QUIET, SOFT_LEG, initial_motor_angle_rad=1.25)
    assert log.velocity_command_rad_s.max() <= 0.0
    assert log.motor_angle_rad.max() <= 1.25 + 1e-12


def test_runaway_torque_ends_with_motor_off():
    stiff_leg = FreeLeg(mass_kg=50.0, damping_ns_per_m=500.0, stiffness_n_per_m=1e6)
    fd = np.zeros(2000)
    fd[100:] = 400.0  # 400 N x 0.7 m >> 120 N m
    log = simulate_device(fd, QUIET, stiff_leg)
    events = safety_events(log)
    off = events[events.state == SAFETY_MOTOR_OFF_TORQUE]
    assert len(off) == 1
    t_off = off.time_s.iloc[0]
    after = log.time_s >= t_off
    assert (log.safety_state[after] == SAFETY_MOTOR_OFF_TORQUE).all()  # latched
    assert (log.velocity_command_rad_s[after] == 0).all()
    # when it switched off, the torque exceeded the limit
    k = round(t_off * DEV.sample_rate_hz)
    torque = DEV.lever_arm_m * log.force_measured_n.to_numpy()[k]
    assert abs(torque) > 0.9 * DEV.motor_cutoff_torque_nm
    assert events.name.iloc[-1] == "motor_off_torque"


def test_velocity_cutoff_with_a_misconfigured_limiter():
    dev = DeviceParameters(
        velocity_limit_rad_s=20.0,
        acceleration_limit_rad_s2=5000.0,
        motor_cutoff_torque_nm=1e4,
        loadcell_noise_sd_n=0.0,
        loadcell_resolution_n=0.0,
    )
    fd = np.zeros(2000)
    fd[100:] = 200.0
    log = simulate_device(fd, dev, SOFT_LEG)
    events = safety_events(log)
    assert "motor_off_velocity" in set(events.name)
    k = int(np.argmax(log.safety_state.to_numpy() == SAFETY_MOTOR_OFF_VELOCITY))
    assert abs(log.motor_velocity_rad_s.iloc[k]) > dev.motor_cutoff_velocity_rad_s


@pytest.mark.parametrize(
    ("angle", "state"),
    [(1.32, SAFETY_MOTOR_OFF_POSITION), (-1.32, SAFETY_MOTOR_OFF_POSITION), (1.35, SAFETY_SERVO_OFF_POSITION)],
)
def test_position_cutoffs(angle, state):
    log = simulate_device(np.zeros(200), QUIET, initial_motor_angle_rad=angle)
    assert log.safety_state.iloc[0] == state
    assert (log.safety_state == state).all()
    assert (log.velocity_command_rad_s == 0).all()


def test_motor_off_coasts_under_the_rod_force():
    # switched off with the rods pre-loaded: the lever is pushed back by the leg and slows by friction
    log = simulate_device(np.zeros(3000), QUIET, FreeLeg(), initial_motor_angle_rad=1.32)
    th = log.motor_angle_rad.to_numpy()
    assert th[-1] < th[0]  # the compressed rods push the free motor back
    assert np.isfinite(th).all()


def test_seed_gives_same_noise():
    fd = np.zeros(500)
    a = simulate_device(fd, DEV, seed=3)
    b = simulate_device(fd, DEV, seed=3)
    assert a.equals(b)
    assert not a.equals(simulate_device(fd, DEV, seed=4))
    # load-cell noise plus the loop's response to it (the admittance moves the leg a little)
    assert DEV.loadcell_noise_sd_n <= a.force_measured_n.std() <= 1.3 * DEV.loadcell_noise_sd_n


def test_bad_inputs_are_refused():
    with pytest.raises(LoperInputError, match="sample 3"):
        simulate_device(np.array([0, 0, 0, np.nan, 0.0]))
    with pytest.raises(LoperInputError, match="rod_stiffness_n_per_m"):
        DeviceParameters(rod_stiffness_n_per_m=-1.0)
    with pytest.raises(LoperInputError, match="brace_position_m"):
        simulate_device(np.zeros(10), DEV, None)


# --------------------------------------------------------------------------- the leg from the config


def test_free_leg_from_config_holds_every_key():
    leg = stage_settings(
        device_config(leg={"mass_kg": 9.5, "damping_ns_per_m": 4.0, "stiffness_n_per_m": 120.0}), "device"
    ).leg
    assert (leg.mass_kg, leg.damping_ns_per_m, leg.stiffness_n_per_m) == (9.5, 4.0, 120.0)


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("mass_kg", 0.0, "device.leg.mass_kg must be positive, got 0.0"),
        ("damping_ns_per_m", -1.0, "device.leg.damping_ns_per_m must be finite and >= 0, got -1.0"),
        ("stiffness_n_per_m", float("nan"), "device.leg.stiffness_n_per_m must be finite and >= 0, got nan"),
    ],
)
def test_a_bad_leg_value_is_refused_naming_its_key(key, value, message):
    leg = {"mass_kg": 14.0, "damping_ns_per_m": 10.0, "stiffness_n_per_m": 250.0, key: value}
    with pytest.raises(LoperInputError) as info:
        _ = stage_settings(device_config(leg=leg), "device").leg
    assert str(info.value) == message
