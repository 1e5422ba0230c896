"""The compiled kernels of the swing-leg model (loper_analysis.swing_leg.kernels).

Known answers: the Cholesky solve against NumPy's; the feedback torques written out from the joint angles'
definitions; the RK4 of the deviation dynamics against SciPy's ``solve_ivp`` (DOP853, rtol 1e-11) on the
same equations of motion in absolute coordinates, for a moving reference, a pelvis deviation, a smooth rod
force and a start off the reference.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from loper_analysis.swing_leg import kernels
from loper_analysis.swing_leg.dynamics import inverse_dynamics, joint_angles
from tests.parameter_sets import ASYMMETRIC, WINTER
from tests.swing_leg.reference_dynamics import forward_dynamics, generalized_joint_forces


def test_segment_slots_and_scalars_fill_the_packed_vector_once_each():
    slots = [kernels.CART_MASS, kernels.ATTACHMENT, kernels.GRAVITY, kernels.SHANK_ATTACHMENT]
    slots += [kernels.segment_slot(i) + k for i in range(3) for k in range(5)]
    assert sorted(slots) == list(range(kernels.N_PACKED))
    packed = ASYMMETRIC.packed
    assert packed[kernels.segment_slot(1)] == 3.4  # the shank's mass
    assert packed[kernels.segment_slot(2) + 2] == 0.26  # the foot's length
    assert packed[kernels.ATTACHMENT] == 0.29 and packed[kernels.GRAVITY] == 9.79


def test_solve4_matches_numpy_and_leaves_the_cholesky_factor_in_the_lower_triangle(rng):
    x = rng.normal(size=(4, 4))
    spd = x @ x.T + 4.0 * np.eye(4)
    r = rng.normal(size=4)
    work = spd.copy()
    out = np.empty(4)
    kernels.solve4(work, r, out)
    np.testing.assert_allclose(out, np.linalg.solve(spd, r), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(np.tril(work), np.linalg.cholesky(spd), rtol=1e-12, atol=1e-14)


def test_feedback_torques_are_stiffness_and_damping_times_the_joint_deviations():
    e = np.array([0.01, 0.1, 0.3, 0.25])  # cart, thigh, shank, foot
    ed = np.array([0.2, -1.0, 2.0, 0.5])
    dpel, dpeld = 0.04, -0.3
    p = np.array([75.0, 2.0, 40.0, 1.0, 20.0, 0.5])
    T = np.empty(3)
    kernels.feedback_torques(e, ed, dpel, dpeld, p, T)
    # hip flexion = pelvis - thigh, knee flexion = shank - thigh, ankle dorsiflexion = shank - foot
    expected = [
        -75.0 * (0.04 - 0.1) - 2.0 * (-0.3 + 1.0),
        -40.0 * (0.3 - 0.1) - 1.0 * (2.0 + 1.0),
        -20.0 * (0.3 - 0.25) - 0.5 * (2.0 - 0.5),
    ]
    np.testing.assert_allclose(T, expected, rtol=1e-14)
    # the same from the model's own joint-angle definition
    dtheta = joint_angles(e, dpel)
    dtheta_d = joint_angles(ed, dpeld)
    np.testing.assert_allclose(T, -p[0::2] * dtheta - p[1::2] * dtheta_d, rtol=1e-14)


def test_terms_batch_fills_one_state_per_row_as_terms_does():
    q = np.array([[0.0, 0.3, -0.2, 0.1], [0.05, -0.4, 0.6, 0.9]])
    qd = np.array([[0.1, 1.0, -2.0, 0.5], [0.0, -0.5, 3.0, 1.0]])
    M, h, Ja = kernels.terms_batch(q, qd, WINTER.packed)
    for k in range(2):
        Mk, hk, Jk = np.empty((4, 4)), np.empty(4), np.empty((4, 4))
        kernels.terms(q[k], qd[k], WINTER.packed, Mk, hk, Jk)
        np.testing.assert_array_equal(M[k], Mk)
        np.testing.assert_array_equal(h[k], hk)
        np.testing.assert_array_equal(Ja[k], Jk)
    # at rest the cart row of M holds the whole mass, and a pushed cart moves the attachment point with it
    total = WINTER.cart_mass_kg + sum(WINTER.mass_kg)
    assert M[0, 0, 0] == pytest.approx(total, rel=1e-14)
    np.testing.assert_array_equal(Ja[:, :, 0], [[1.0, 0.0, 1.0, 0.0], [1.0, 0.0, 1.0, 0.0]])
    d = WINTER.attachment_m
    np.testing.assert_allclose(Ja[1, :2, 1], [-d * np.cos(-0.4), d * np.sin(-0.4)], rtol=1e-14)
    # the shank rod's point moves with the whole thigh (the knee) and its own distance along the shank
    L = WINTER.length_m[0]
    np.testing.assert_allclose(Ja[1, 2:, 1], [-L * np.cos(-0.4), L * np.sin(-0.4)], rtol=1e-14)
    np.testing.assert_array_equal(Ja[:, 2:, 2], 0.0)  # no shank rod: its point is the knee
    two = WINTER.replace(shank_attachment_m=SHANK_ROD_M)
    _, _, J2 = kernels.terms_batch(q, qd, two.packed)
    np.testing.assert_allclose(J2[1, 2:, 2], [-SHANK_ROD_M * np.cos(0.6), SHANK_ROD_M * np.sin(0.6)], rtol=1e-14)
    np.testing.assert_array_equal(J2[:, :, 3], 0.0)  # neither rod moves with the foot
    np.testing.assert_array_equal(J2[:, :2], Ja[:, :2])  # the thigh rod's as before


# ---------------------------------------------------------------- RK4 of the deviation against solve_ivp

AMPLITUDE = np.array([0.01, 0.3, 0.5, 0.2])
OMEGA = np.array([3.0, 5.0, 7.0, 4.0])
OFFSET = np.array([0.0, -0.2, 0.1, 0.3])


def _reference(t):
    """A smooth moving reference q_ref(t) and its first two derivatives, (n, 4) each."""
    t = np.atleast_1d(t)[:, None]
    q = OFFSET + AMPLITUDE * np.sin(OMEGA * t)
    qd = AMPLITUDE * OMEGA * np.cos(OMEGA * t)
    qdd = -AMPLITUDE * OMEGA**2 * np.sin(OMEGA * t)
    return q, qd, qdd


#: The pulse's end: on a step boundary and an output sample, where the force's slope jumps.
PULSE_S = 0.09375


def _rod_force(t):
    """A 40 N forward half-sine pulse over the first :data:`PULSE_S` with a small vertical part, (n, 2)."""
    t = np.atleast_1d(t)
    on = (t >= 0) & (t <= PULSE_S)
    fx = np.where(on, 40.0 * np.sin(np.pi * t / PULSE_S), 0.0)
    return np.column_stack([fx, -0.25 * fx])


def _shank_force(t):
    """A 30 N backward half-sine pulse at the shank over the second half of :data:`PULSE_S`, (n, 2)."""
    t = np.atleast_1d(t)
    on = (t >= 0.5 * PULSE_S) & (t <= PULSE_S)
    fx = np.where(on, -30.0 * np.sin(np.pi * (t / PULSE_S - 0.5) * 2.0), 0.0)
    return np.column_stack([fx, 0.4 * fx])


#: The shank rod just above the ankle: 0.35 m below the knee (Winter's shank is 0.43 m at 1.75 m).
SHANK_ROD_M = 0.35


def _pelvis_deviation(t):
    """Pelvis angle deviation and its rate, (n, 2)."""
    t = np.atleast_1d(t)
    return np.column_stack([0.03 * np.sin(6.0 * t), 0.18 * np.cos(6.0 * t)])


def _peer(params, impedance, e0, ed0, t_out, shank=False, stiffness=None):
    """The absolute model q = q_ref + e under u_ff = inverse dynamics of the reference, the rod force (and, with
    ``shank``, the shank rod's) and the joint feedback about the reference angles, integrated by DOP853; with
    ``stiffness`` (3, 3) a full joint stiffness matrix in place of ``impedance``'s diagonal K."""

    def rhs(t, y):
        q, qd = y[:4], y[4:]
        q_ref, qd_ref, qdd_ref = _reference(t)
        u_ff = inverse_dynamics(q_ref, qd_ref, qdd_ref, params)[0]
        pel, peld = _pelvis_deviation(t)[0]
        dth = joint_angles(q, pel) - joint_angles(q_ref[0], 0.0)
        dthd = joint_angles(qd, peld) - joint_angles(qd_ref[0], 0.0)
        spring = impedance[0::2] * dth if stiffness is None else stiffness @ dth
        torques = -spring - impedance[1::2] * dthd
        u = u_ff + generalized_joint_forces(torques)
        shank_force = _shank_force(t) if shank else None
        return np.concatenate([qd, forward_dynamics(q, qd, u, params, _rod_force(t), shank_force)])

    q0, qd0, _ = _reference(0.0)
    y0 = np.concatenate([q0[0] + e0, qd0[0] + ed0])
    ys = [y0[:, None]]
    kinks = (0.0, 0.5 * PULSE_S, PULSE_S, t_out[-1]) if shank else (0.0, PULSE_S, t_out[-1])
    for span in zip(kinks[:-1], kinks[1:], strict=True):  # across the kinks of the pulses, not over them
        t_eval = t_out[(t_out > span[0]) & (t_out <= span[1])]
        sol = solve_ivp(rhs, span, ys[-1][:, -1], method="DOP853", t_eval=t_eval, rtol=1e-11, atol=1e-13)
        assert sol.success
        ys.append(sol.y)
    y = np.hstack(ys)
    q_ref, qd_ref, _ = _reference(t_out)
    return y[:4].T - q_ref, y[4:].T - qd_ref


@pytest.mark.parametrize(
    ("params", "shank"),
    [(WINTER, False), (ASYMMETRIC, False), (WINTER.replace(shank_attachment_m=SHANK_ROD_M), True)],
    ids=["winter", "asymmetric", "winter-two-rods"],
)
def test_rk4_of_the_deviation_matches_dop853_on_the_same_equations(params, shank):
    dt, n_sub, n_out = 1.0 / 2048.0, 8, 33  # 32 output samples 1/256 s apart: 0.125 s
    n_steps = n_sub * (n_out - 1)
    stages = 0.5 * dt * np.arange(2 * n_steps + 1)  # every stage time, dt / 2 apart
    ref_q, ref_qd, ref_qdd = _reference(stages)
    # w = u_ff - Ja(q_ref)^T F_u with no unperturbed force: the reference's own inverse dynamics
    w = inverse_dynamics(ref_q, ref_qd, ref_qdd, params)
    step_start = dt * np.arange(n_steps)
    fp = np.stack([_rod_force(step_start + c * dt) for c in (0.0, 0.5, 0.5, 1.0)], axis=1)
    fs = np.stack([_shank_force(step_start + c * dt) for c in (0.0, 0.5, 0.5, 1.0)], axis=1) * shank
    P = np.array([[75.0, 2.0, 40.0, 1.0, 20.0, 0.5], [150.0, 0.5, 10.0, 3.0, 60.0, 0.2]])
    e0 = np.array([0.002, -0.01, 0.02, 0.005])
    ed0 = np.array([0.0, 0.1, -0.2, 0.05])

    E, Ed = kernels.simulate_deviation_batch(
        P, params.packed, ref_q, ref_qd, ref_qdd, w, fp, fs, _pelvis_deviation(stages), e0, ed0, dt, n_sub, n_out
    )
    assert E.shape == Ed.shape == (2, n_out, 4)
    t_out = n_sub * dt * np.arange(n_out)
    for b in range(2):
        e_peer, ed_peer = _peer(params, P[b], e0, ed0, t_out, shank)
        assert np.abs(e_peer - e0).max() > 0.01  # the pulse moves the leg well away from its start
        np.testing.assert_allclose(E[b], e_peer, rtol=0, atol=1e-9)
        np.testing.assert_allclose(Ed[b], ed_peer, rtol=0, atol=5e-8)
    assert np.abs(E[0] - E[1]).max() > 1e-3  # each parameter set integrates on its own


def test_without_perturbation_the_deviation_stays_exactly_zero():
    dt, n_sub, n_out = 1.0 / 512.0, 2, 9
    n_steps = n_sub * (n_out - 1)
    stages = 0.5 * dt * np.arange(2 * n_steps + 1)
    ref_q, ref_qd, ref_qdd = _reference(stages)
    w = inverse_dynamics(ref_q, ref_qd, ref_qdd, WINTER)
    E, Ed = kernels.simulate_deviation_batch(
        np.array([[75.0, 2.0, 40.0, 1.0, 20.0, 0.5]]),
        WINTER.packed,
        ref_q,
        ref_qd,
        ref_qdd,
        w,
        np.zeros((n_steps, 4, 2)),
        np.zeros((n_steps, 4, 2)),
        np.zeros((len(stages), 2)),
        np.zeros(4),
        np.zeros(4),
        dt,
        n_sub,
        n_out,
    )
    np.testing.assert_allclose(E, 0.0, atol=1e-12)
    np.testing.assert_allclose(Ed, 0.0, atol=1e-10)
