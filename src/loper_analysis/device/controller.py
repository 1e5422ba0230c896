"""Time-domain simulation of the admittance-controlled LOPER interacting with a leg.

Block arrangement (the study does not fix it; this is our choice, ``docs/device.md``)::

    F_d --H_F--> F_r ----------------------------.
                                                  v
            .--> (+) e = F_r - F_m         w = c F_r - F_m
            |          |                          |
            |     H_C: I_v v_d' + B_v v_d = r (e + K_a w')      admittance, 1 kHz
            |          |
            |     PVA limiter (velocity, acceleration, position bound)   safety
            |          | v_cmd   (+ servo delay)
            |     H_A: servo velocity loop, 2nd order (f_s, zeta_s)      motor angle theta
            |          |
            |     rods + brace: F_m = k_r (r theta - x_b) + b_r (r theta' - x_b')
            |          |
            |     H_H: leg at the brace: free-hanging m x_b'' + b x_b' + k x_b = F_m,
            |          or a prescribed brace motion x_b(t) (walking; the leg is
            |          far stronger than the device)
            '---- load cell: F_m + white noise, quantised ---'

* ``r`` is the rod moment arm (lever length) that turns the force into a
  torque and the motor angle into brace translation.
* ``c`` is a set-point weight on the lead term ``K_a s`` (the numerator
  ``K_a s + 1`` of H_C): the measured force gets the full lead (interaction
  stability), the desired force only the fraction ``c`` (less overshoot on
  reference steps). This is the classic two-degree-of-freedom arrangement.
* H_F is a 2nd-order low-pass (cut-off, damping) on the desired force.
* The servo is a black box: a stiff velocity loop (motor velocity follows
  the command through a 2nd-order low-pass) plus a transport delay.
* Safety layer: the PVA limiter clamps the commanded velocity (+-4.71 rad/s),
  its rate (+-500 rad/s^2) and, near the position bound (+-1.22 rad), the
  velocity towards it to ``sqrt(2 a_max (bound - |theta|))`` (constant
  deceleration), with no outward motion beyond the bound. The motor is cut
  off at |theta| > 1.31 rad, |theta'| > 6.28 rad/s or |torque| > 120 N m,
  the servo at |theta| > 1.34 rad; a cut-off latches: the motor then coasts
  (lever inertia, viscous friction) under the rod force. Every sample's
  safety state goes into the log.

The controller and limiter run at the control rate (1000 Hz); the linear
plant (servo, rods, leg) is advanced exactly between samples (matrix
exponential, zero-order hold on the velocity command).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd
from numba import njit

from loper_analysis.errors import LoperInputError

__all__ = [
    "DeviceParameters",
    "FreeLeg",
    "SAFETY_OK",
    "SAFETY_LIMITED",
    "SAFETY_MOTOR_OFF_POSITION",
    "SAFETY_MOTOR_OFF_VELOCITY",
    "SAFETY_MOTOR_OFF_TORQUE",
    "SAFETY_SERVO_OFF_POSITION",
    "simulate_device",
    "safety_events",
]

SAFETY_OK = 0
SAFETY_LIMITED = 1
SAFETY_MOTOR_OFF_POSITION = 2
SAFETY_MOTOR_OFF_VELOCITY = 3
SAFETY_MOTOR_OFF_TORQUE = 4
SAFETY_SERVO_OFF_POSITION = 5
_SAFETY_NAMES = {
    SAFETY_OK: "ok",
    SAFETY_LIMITED: "limited",
    SAFETY_MOTOR_OFF_POSITION: "motor_off_position",
    SAFETY_MOTOR_OFF_VELOCITY: "motor_off_velocity",
    SAFETY_MOTOR_OFF_TORQUE: "motor_off_torque",
    SAFETY_SERVO_OFF_POSITION: "servo_off_position",
}


@dataclass(frozen=True)
class DeviceParameters:
    """Constants of the LOPER and its controller (SI units; config key ``device``).

    Controller constants (I_v, B_v, K_a, c) and safety limits are the study's.
    The black-box parts (prefilter, servo, rods/brace) were tuned (Nelder-Mead
    on the simulated device-test trials of :mod:`.trials`, analysed like
    recorded ones) so that the simulated device reproduces the study's device
    figures on a free-hanging leg (``FreeLeg()``): bandwidth 38.7 Hz (study
    39), rise time 9.9 ms (9.7-10.3), overshoot 30.5 % (29-32), steady state
    35.2 N for 40 N (36); in minimal-impedance walking (prescribed brace
    motion, hip +-0.3 rad) RMS 1.9 N and max 4.6 N (2.0-2.1 and 4.5-4.6).
    """

    sample_rate_hz: float = 1000.0
    virtual_inertia_kg_m2: float = 0.2
    virtual_damping_nms_per_rad: float = 3.0
    lead_time_s: float = 0.017
    setpoint_weight: float = 0.5
    lever_arm_m: float = 0.7
    prefilter_cutoff_hz: float = 34.1
    prefilter_damping: float = 0.644
    servo_bandwidth_hz: float = 29.97
    servo_damping: float = 0.716
    servo_delay_s: float = 0.002
    rod_stiffness_n_per_m: float = 3390.0
    rod_damping_ns_per_m: float = 26.05
    motor_inertia_kg_m2: float = 0.05
    motor_friction_nms_per_rad: float = 0.5
    loadcell_noise_sd_n: float = 0.2
    loadcell_resolution_n: float = 0.01
    velocity_limit_rad_s: float = 4.71
    acceleration_limit_rad_s2: float = 500.0
    position_bound_rad: float = 1.22
    motor_cutoff_position_rad: float = 1.31
    motor_cutoff_velocity_rad_s: float = 6.28
    motor_cutoff_torque_nm: float = 120.0
    servo_cutoff_position_rad: float = 1.34

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not np.isfinite(value):
                raise LoperInputError(f"device parameter {name} must be finite, got {value}")
            if value < 0:
                raise LoperInputError(f"device parameter {name} must be >= 0, got {value}")
        for name in (
            "sample_rate_hz",
            "virtual_inertia_kg_m2",
            "lever_arm_m",
            "prefilter_cutoff_hz",
            "servo_bandwidth_hz",
            "rod_stiffness_n_per_m",
            "motor_inertia_kg_m2",
        ):
            if getattr(self, name) <= 0:
                raise LoperInputError(f"device parameter {name} must be positive, got {getattr(self, name)}")
        if not (self.position_bound_rad < self.motor_cutoff_position_rad <= self.servo_cutoff_position_rad):
            raise LoperInputError(
                "device limits must satisfy position_bound_rad < motor_cutoff_position_rad <= "
                f"servo_cutoff_position_rad, got {self.position_bound_rad}, {self.motor_cutoff_position_rad}, "
                f"{self.servo_cutoff_position_rad}"
            )


@dataclass(frozen=True)
class FreeLeg:
    """A free-hanging leg seen at the brace: m x'' + b x' + k x = F (kg, N s/m, N/m)."""

    mass_kg: float = 14.0
    damping_ns_per_m: float = 10.0
    stiffness_n_per_m: float = 250.0

    def __post_init__(self) -> None:
        for name, value in asdict(self).items():
            if not np.isfinite(value) or value < 0:
                raise LoperInputError(f"device.leg.{name} must be finite and >= 0, got {value}")
        if self.mass_kg <= 0:
            raise LoperInputError(f"device.leg.mass_kg must be positive, got {self.mass_kg}")


def _plant_matrices(dev: DeviceParameters, leg: FreeLeg | None):
    """Continuous state-space models (servo on / motor off) and their exact 1-sample discretisation.

    Servo on, state [theta, omega, alpha, x_b, v_b]; motor off, state
    [theta, omega, 0, x_b, v_b] (alpha unused). Input: [v_cmd, x_p, v_p, a_p]
    (prescribed brace motion; zero for the free leg).
    """
    T = 1.0 / dev.sample_rate_hz
    ws = 2 * np.pi * dev.servo_bandwidth_hz
    zs = dev.servo_damping
    r, kr, br = dev.lever_arm_m, dev.rod_stiffness_n_per_m, dev.rod_damping_ns_per_m
    on = np.zeros((5, 5))
    on[0, 1] = 1.0
    on[1, 2] = 1.0
    on[2, 1] = -ws * ws
    on[2, 2] = -2 * zs * ws
    off = np.zeros((5, 5))
    off[0, 1] = 1.0
    Jm, bm = dev.motor_inertia_kg_m2, dev.motor_friction_nms_per_rad
    # motor off: Jm omega' = -r F_m - bm omega
    Bon = np.zeros((5, 4))
    Bon[2, 0] = ws * ws
    Boff = np.zeros((5, 4))
    if leg is not None:
        m, b, k = leg.mass_kg, leg.damping_ns_per_m, leg.stiffness_n_per_m
        for A in (on, off):
            A[3, 4] = 1.0
            # m v_b' = kr (r theta - x_b) + br (r omega - v_b) - b v_b - k x_b
            A[4, 0] = kr * r / m
            A[4, 1] = br * r / m
            A[4, 3] = -(kr + k) / m
            A[4, 4] = -(br + b) / m
        off[1, 0] = -r * kr * r / Jm
        off[1, 1] = -(r * br * r + bm) / Jm
        off[1, 3] = r * kr / Jm
        off[1, 4] = r * br / Jm
    else:
        # prescribed brace: x_b, v_b are inputs (held in the state for output only)
        off[1, 0] = -r * kr * r / Jm
        off[1, 1] = -(r * br * r + bm) / Jm
        Boff[1, 1] = r * kr / Jm
        Boff[1, 2] = r * br / Jm
    from scipy.linalg import (
        expm,  # imported here, as bilinear below: importing the module stays cheap
    )

    out = []
    for A, B in ((on, Bon), (off, Boff)):
        n = A.shape[0]
        big = np.zeros((n + 4, n + 4))
        big[:n, :n] = A * T
        big[:n, n:] = B * T
        E = expm(big)
        out.append((np.ascontiguousarray(E[:n, :n]), np.ascontiguousarray(E[:n, n:])))
    return out


def _filter_coefficients(dev: DeviceParameters):
    """Discrete (Tustin) coefficients of H_F and of the two admittance paths."""
    from scipy.signal import (
        bilinear,  # imported here: scipy.signal costs ~1 s per process
    )

    fs = dev.sample_rate_hz
    wf = 2 * np.pi * dev.prefilter_cutoff_hz
    bF, aF = bilinear([wf * wf], [1.0, 2 * dev.prefilter_damping * wf, wf * wf], fs)
    Iv, Bv, Ka = dev.virtual_inertia_kg_m2, dev.virtual_damping_nms_per_rad, dev.lead_time_s
    b1, a1 = bilinear([1.0], [Iv, Bv], fs)  # e -> v_d
    b2, a2 = bilinear([Ka, 0.0], [Iv, Bv], fs)  # w -> v_d (lead)

    def pad(v):
        return np.pad(np.asarray(v, float), (0, 3 - len(v)))

    return np.stack([pad(bF), pad(aF), pad(b1), pad(a1), pad(b2), pad(a2)])


@njit(cache=True)
def _limited_velocity(vd, vd_prev, th, vmax, dv_max, amax, pbound):
    """The velocity command (rad/s) after the PVA limiter and whether it limited it.

    ``vd`` is the admittance's command and ``vd_prev`` the previous limited command (rad/s), ``th`` the motor
    angle (rad); limits: speed ``vmax`` (rad/s), change per sample ``dv_max`` (rad/s), and near the position
    bound ``pbound`` (rad) the constant deceleration ``amax`` (rad/s^2) towards it, no outward motion beyond it.
    """
    limited = False
    if vd > vmax:
        vd, limited = vmax, True
    elif vd < -vmax:
        vd, limited = -vmax, True
    dv = vd - vd_prev
    if dv > dv_max:
        vd, limited = vd_prev + dv_max, True
    elif dv < -dv_max:
        vd, limited = vd_prev - dv_max, True
    # the position bound has the last word: constant deceleration towards it,
    # no outward motion beyond it
    room = pbound - abs(th)
    vtoward = np.sqrt(2.0 * amax * room) if room > 0 else 0.0
    if th >= 0 and vd > vtoward:
        vd, limited = vtoward, True
    elif th < 0 and vd < -vtoward:
        vd, limited = -vtoward, True
    return vd, limited


@njit(cache=True)
def _cutoff_state(th, omega, torque, spos, mpos, mvel, mtorque):
    """The safety state a cut-off latches (servo off 5, motor off at the position 2, velocity 3 or torque 4),
    0 when none trips: motor angle ``th`` (rad), velocity ``omega`` (rad/s) and torque (N m) against their
    cut-offs."""
    if abs(th) > spos:
        return 5
    if abs(th) > mpos:
        return 2
    if abs(omega) > mvel:
        return 3
    if abs(torque) > mtorque:
        return 4
    return 0


@njit(cache=True)
def _run(coef, Aon, Bon, Aoff, Boff, consts, fd, noise, xp, vp, ap, free_leg, x0):
    """The 1 kHz loop; returns the log columns and the safety state per sample."""
    n = fd.shape[0]
    r, kr, br, Jm, res = consts[0], consts[1], consts[2], consts[3], consts[4]
    vmax, amax, pbound = consts[5], consts[6], consts[7]
    mpos, mvel, mtorque, spos = consts[8], consts[9], consts[10], consts[11]
    T, delay = consts[12], int(consts[13])
    fm_out = np.empty(n)
    th_out = np.empty(n)
    om_out = np.empty(n)
    vcmd_out = np.empty(n)
    state_out = np.zeros(n, np.int64)
    x = x0.copy()
    u = np.zeros(4)
    # filter states (direct form I histories)
    fd1 = fd2 = fr1 = fr2 = 0.0
    e1 = v1a = 0.0
    w1 = v2a = 0.0
    vd_prev = 0.0
    buf = np.zeros(delay + 1)
    latched = 0
    for k in range(n):
        xb = x[3] if free_leg else xp[k]
        vb = x[4] if free_leg else vp[k]
        f_true = kr * (r * x[0] - xb) + br * (r * x[1] - vb)
        fm = f_true + noise[k]
        if res > 0:
            fm = res * np.round(fm / res)
        # prefilter
        fr = (coef[0, 0] * fd[k] + coef[0, 1] * fd1 + coef[0, 2] * fd2 - coef[1, 1] * fr1 - coef[1, 2] * fr2) / coef[
            1, 0
        ]
        fd2, fd1, fr2, fr1 = fd1, fd[k], fr1, fr
        e = r * (fr - fm)
        w = r * (consts[14] * fr - fm)
        va = (coef[2, 0] * e + coef[2, 1] * e1 - coef[3, 1] * v1a) / coef[3, 0]
        vb2 = (coef[4, 0] * w + coef[4, 1] * w1 - coef[5, 1] * v2a) / coef[5, 0]
        e1, v1a, w1, v2a = e, va, w, vb2
        vd = va + vb2
        th = x[0]
        vd, limited = _limited_velocity(vd, vd_prev, th, vmax, amax * T, amax, pbound)
        vd_prev = vd
        # servo delay
        for i in range(delay):
            buf[i] = buf[i + 1]
        buf[delay] = vd
        vcmd = buf[0]
        # cut-offs (latching)
        torque = Jm * x[2] + r * f_true
        if latched == 0:
            latched = _cutoff_state(th, x[1], torque, spos, mpos, mvel, mtorque)
        fm_out[k] = fm
        th_out[k] = th
        om_out[k] = x[1]
        vcmd_out[k] = vd if latched == 0 else 0.0  # what the controller sends (the delay is the servo's)
        state_out[k] = latched if latched else (1 if limited else 0)
        # advance the plant one sample
        u[0] = vcmd
        if not free_leg:
            u[1] = xp[k]
            u[2] = vp[k]
            u[3] = ap[k]
        if latched:
            x = Aoff @ x + Boff @ u
            x[2] = 0.0
        else:
            x = Aon @ x + Bon @ u
        if not free_leg:
            x[3] = xp[min(k + 1, n - 1)]
            x[4] = vp[min(k + 1, n - 1)]
    return fm_out, th_out, om_out, vcmd_out, state_out


def simulate_device(
    desired_force_n,
    device: DeviceParameters = DeviceParameters(),
    leg: FreeLeg | None = FreeLeg(),
    *,
    brace_position_m=None,
    seed: int | np.random.SeedSequence = 0,
    initial_motor_angle_rad: float = 0.0,
) -> pd.DataFrame:
    """Simulate the controlled device at its control rate.

    Parameters
    ----------
    desired_force_n : (n,) desired interaction force per control sample (N).
    device : controller, actuator and safety constants.
    leg : a free-hanging leg, or None with ``brace_position_m`` (n,) giving a
        prescribed brace motion (m, forward positive; walking).
    seed : load-cell noise seed.

    Returns
    -------
    DataFrame with the robot-log channels ``time_s``, ``force_desired_n``,
    ``force_measured_n``, ``motor_angle_rad``, ``motor_velocity_rad_s``,
    ``safety_state`` and the command ``velocity_command_rad_s``.
    """
    fd = np.asarray(desired_force_n, dtype=float)
    if fd.ndim != 1 or fd.size < 2:
        raise LoperInputError(f"desired_force_n must be 1-D with >= 2 samples, got shape {fd.shape}")
    if not np.all(np.isfinite(fd)):
        raise LoperInputError(f"desired_force_n is not finite at sample {int(np.argmax(~np.isfinite(fd)))}")
    n = fd.size
    T = 1.0 / device.sample_rate_hz
    if leg is None:
        if brace_position_m is None:
            raise LoperInputError("without a free leg, brace_position_m (prescribed brace motion) is required")
        xp = np.asarray(brace_position_m, dtype=float)
        if xp.shape != (n,) or not np.all(np.isfinite(xp)):
            raise LoperInputError(f"brace_position_m must be finite with shape ({n},), got {xp.shape}")
        vp = np.gradient(xp, T)
        ap = np.gradient(vp, T)
    else:
        xp = vp = ap = np.zeros(n)
    (Aon, Bon), (Aoff, Boff) = _plant_matrices(device, leg)
    rng = np.random.default_rng(seed)
    noise = rng.normal(0.0, device.loadcell_noise_sd_n, n) if device.loadcell_noise_sd_n > 0 else np.zeros(n)
    consts = np.array(
        [
            device.lever_arm_m,
            device.rod_stiffness_n_per_m,
            device.rod_damping_ns_per_m,
            device.motor_inertia_kg_m2,
            device.loadcell_resolution_n,
            device.velocity_limit_rad_s,
            device.acceleration_limit_rad_s2,
            device.position_bound_rad,
            device.motor_cutoff_position_rad,
            device.motor_cutoff_velocity_rad_s,
            device.motor_cutoff_torque_nm,
            device.servo_cutoff_position_rad,
            T,
            round(device.servo_delay_s * device.sample_rate_hz),
            device.setpoint_weight,
        ]
    )
    x0 = np.zeros(5)
    x0[0] = initial_motor_angle_rad
    if leg is None:
        x0[0] = initial_motor_angle_rad if initial_motor_angle_rad else xp[0] / device.lever_arm_m
        x0[3], x0[4] = xp[0], vp[0]
    fm, th, om, vcmd, state = _run(
        _filter_coefficients(device), Aon, Bon, Aoff, Boff, consts, fd, noise, xp, vp, ap, leg is not None, x0
    )
    return pd.DataFrame(
        {
            "time_s": np.arange(n) * T,
            "force_desired_n": fd,
            "force_measured_n": fm,
            "motor_angle_rad": th,
            "motor_velocity_rad_s": om,
            "safety_state": state,
            "velocity_command_rad_s": vcmd,
        }
    )


def safety_events(log: pd.DataFrame) -> pd.DataFrame:
    """When the safety state changed: columns ``time_s``, ``state``, ``name`` (one row per change)."""
    s = log["safety_state"].to_numpy()
    change = np.flatnonzero(np.diff(s, prepend=-1) != 0)
    return pd.DataFrame(
        {
            "time_s": log["time_s"].to_numpy()[change],
            "state": s[change],
            "name": [_SAFETY_NAMES[int(v)] for v in s[change]],
        }
    )
