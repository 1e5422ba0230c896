"""Inter-joint (bi-articular) stiffness in the compiled kernels (loper_analysis.swing_leg.kernels).

Known answers: the feedback torques of a symmetric stiffness matrix written out from the joint angles'
definitions; the RK4 of the deviation dynamics with hip-knee and knee-ankle couplings against SciPy's
``solve_ivp`` (DOP853, rtol 1e-11) on the same equations of motion in absolute coordinates, the integration the
uncoupled kernels are checked against; and couplings of zero giving the six-parameter simulation to the bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.swing_leg import kernels
from loper_analysis.swing_leg.dynamics import inverse_dynamics, joint_angles
from tests.parameter_sets import ASYMMETRIC, WINTER
from tests.swing_leg.test_kernels import SHANK_ROD_M, _pelvis_deviation, _reference, _rod_force, _shank_force
from tests.swing_leg.test_kernels import _peer as peer_deviation


def stiffness_matrix(p: np.ndarray) -> np.ndarray:
    """The joint stiffness matrix (3, 3) of hip, knee, ankle from (K_hip, D_hip, ..., D_ankle, K_hk, K_ka)."""
    k_hk, k_ka = p[6], p[7]
    return np.array([[p[0], k_hk, 0.0], [k_hk, p[2], k_ka], [0.0, k_ka, p[4]]])


def test_coupled_feedback_torques_are_the_stiffness_matrix_times_the_joint_deviations():
    e = np.array([0.01, 0.1, 0.3, 0.25])  # cart, thigh, shank, foot
    ed = np.array([0.2, -1.0, 2.0, 0.5])
    dpel, dpeld = 0.04, -0.3
    p = np.array([75.0, 2.0, 40.0, 1.0, 20.0, 0.5, -12.0, 7.0])
    T = np.empty(3)
    kernels.feedback_torques(e, ed, dpel, dpeld, p[:6], T, p[6:])
    dtheta = joint_angles(e, dpel)  # hip flexion, knee flexion, ankle dorsiflexion
    dtheta_d = joint_angles(ed, dpeld)
    np.testing.assert_allclose(T, -stiffness_matrix(p) @ dtheta - p[1::2][:3] * dtheta_d, rtol=1e-14)
    # written out (dtheta = -0.06, 0.2, 0.05 rad; rates 0.7, 3.0, 1.5 rad/s): hip -75 (-0.06) - 2 (0.7) + 12 (0.2),
    # knee -40 (0.2) - 1 (3.0) + 12 (-0.06) - 7 (0.05), ankle -20 (0.05) - 0.5 (1.5) - 7 (0.2)
    np.testing.assert_allclose(T, [4.5 - 1.4 + 2.4, -8.0 - 3.0 - 0.72 - 0.35, -1.0 - 0.75 - 1.4], rtol=1e-14)
    # a positive hip-knee coupling: a knee flexed beyond its course pulls the hip toward extension
    T0, T1 = np.empty(3), np.empty(3)
    bent = np.array([0.0, 0.0, 0.1, 0.1])  # shank and foot rotated together: knee flexion 0.1 rad, ankle 0
    kernels.feedback_torques(bent, np.zeros(4), 0.0, 0.0, np.zeros(6), T0)
    kernels.feedback_torques(bent, np.zeros(4), 0.0, 0.0, np.zeros(6), T1, np.array([10.0, 0.0]))
    np.testing.assert_array_equal(T0, 0.0)
    np.testing.assert_allclose(T1, [-1.0, 0.0, 0.0], rtol=1e-15)


def _peer(params, p, e0, ed0, t_out, shank):
    """The absolute model q = q_ref + e under u_ff = inverse dynamics of the reference, the rod forces and the
    joint feedback T = -K dtheta - D dtheta' with the full stiffness matrix, integrated by DOP853."""
    return peer_deviation(params, np.asarray(p, float)[:6], e0, ed0, t_out, shank, stiffness_matrix(p))


def _kernel_inputs(params, shank):
    dt, n_sub, n_out = 1.0 / 2048.0, 8, 33  # 32 output samples 1/256 s apart: 0.125 s
    n_steps = n_sub * (n_out - 1)
    stages = 0.5 * dt * np.arange(2 * n_steps + 1)
    ref_q, ref_qd, ref_qdd = _reference(stages)
    w = inverse_dynamics(ref_q, ref_qd, ref_qdd, params)
    step_start = dt * np.arange(n_steps)
    fp = np.stack([_rod_force(step_start + c * dt) for c in (0.0, 0.5, 0.5, 1.0)], axis=1)
    fs = np.stack([_shank_force(step_start + c * dt) for c in (0.0, 0.5, 0.5, 1.0)], axis=1) * shank
    e0 = np.array([0.002, -0.01, 0.02, 0.005])
    ed0 = np.array([0.0, 0.1, -0.2, 0.05])
    return (params.packed, ref_q, ref_qd, ref_qdd, w, fp, fs, _pelvis_deviation(stages), e0, ed0, dt, n_sub, n_out)


@pytest.mark.parametrize(
    ("params", "shank"),
    [(WINTER, False), (ASYMMETRIC, False), (WINTER.replace(shank_attachment_m=SHANK_ROD_M), True)],
    ids=["winter", "asymmetric", "winter-two-rods"],
)
def test_rk4_with_couplings_matches_dop853_on_the_same_equations(params, shank):
    """The tolerances of the uncoupled check (1e-9 rad, 5e-8 rad/s): RK4 at 1/2048 s against DOP853 at 1e-11."""
    args = _kernel_inputs(params, shank)
    # a hip-knee coupling of either sign, the second set with a knee-ankle coupling too; each matrix positive
    # definite (|K_hk| < sqrt(K_hip K_knee)), the stiffness a spring-like leg can have
    P = np.array([[75.0, 2.0, 40.0, 1.0, 20.0, 0.5, -30.0, 0.0], [150.0, 0.5, 10.0, 3.0, 60.0, 0.2, 25.0, -15.0]])
    E, Ed = kernels.simulate_deviation_batch(np.ascontiguousarray(P[:, :6]), *args, np.ascontiguousarray(P[:, 6:]))
    E0, _ = kernels.simulate_deviation_batch(np.ascontiguousarray(P[:, :6]), *args)
    t_out = args[-2] * args[-3] * np.arange(args[-1])
    for b in range(2):
        e_peer, ed_peer = _peer(params, P[b], args[8], args[9], t_out, shank)
        np.testing.assert_allclose(E[b], e_peer, rtol=0, atol=1e-9)
        np.testing.assert_allclose(Ed[b], ed_peer, rtol=0, atol=5e-8)
        assert np.abs(E[b] - E0[b]).max() > 1e-3  # the coupling changes the response far beyond the tolerance


def test_zero_couplings_give_the_six_parameter_simulation_to_the_bit():
    args = _kernel_inputs(WINTER.replace(shank_attachment_m=SHANK_ROD_M), True)
    P6 = np.array([[75.0, 2.0, 40.0, 1.0, 20.0, 0.5], [150.0, 0.5, 10.0, 3.0, 60.0, 0.2]])
    E6, Ed6 = kernels.simulate_deviation_batch(P6, *args)
    E8, Ed8 = kernels.simulate_deviation_batch(P6, *args, np.zeros((2, 2)))
    np.testing.assert_array_equal(E8, E6)
    np.testing.assert_array_equal(Ed8, Ed6)
