"""Compiled (numba) kernels of the swing-leg model: equations of motion and RK4.

Everything here works on a packed parameter vector (see
``SegmentParameters.packed``) and plain float64 arrays so that numba can compile
it once (``cache=True``) and the Python layer in :mod:`loper_analysis.swing_leg.dynamics`
and :mod:`loper_analysis.impedance.identification` stays readable.

Packed segment vector ``packed`` (length :data:`N_PACKED`)::

    packed[CART_MASS]                  cart mass (kg)
    packed[segment_slot(i) + 0]        mass of segment i (kg), i = 0 thigh, 1 shank, 2 foot
    packed[segment_slot(i) + 1]        inertia about the COM (kg m^2)
    packed[segment_slot(i) + 2]        length (m): proximal joint -> distal joint along -y
    packed[segment_slot(i) + 3]        COM x in the segment frame (m)
    packed[segment_slot(i) + 4]        COM y in the segment frame (m)
    packed[ATTACHMENT]                 thigh rod's attachment distance from the hip along the thigh (m)
    packed[GRAVITY]                    gravity (m/s^2)
    packed[SHANK_ATTACHMENT]           shank rod's attachment distance from the knee along the shank (m)

The rods' Jacobian ``Ja`` (4 x 4) stacks the thigh rod's attachment point (rows 0, 1: world x, y) over the
shank rod's (rows 2, 3); a rod force vector is ``(F_x, F_y)`` of the thigh rod, then of the shank rod (N).

Segment frame: origin at the proximal joint, x forward and y up when the
segment angle is zero (segment hanging). The global angle q_i is positive when
the distal end moves backward (clockwise seen with the walking direction to the
right), so a body vector v maps to the world as R(-q) v.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

__all__ = [
    "N_PACKED",
    "CART_MASS",
    "ATTACHMENT",
    "GRAVITY",
    "SHANK_ATTACHMENT",
    "segment_slot",
    "terms",
    "solve4",
    "terms_batch",
    "feedback_torques",
    "simulate_deviation_batch",
]

#: Length of the packed parameter vector and the index of its scalar entries.
N_PACKED = 19
CART_MASS = 0
ATTACHMENT = 16
GRAVITY = 17
SHANK_ATTACHMENT = 18


def segment_slot(i: int) -> int:
    """Index of segment ``i``'s first entry (its mass) in the packed vector; 5 entries per segment."""
    return 1 + 5 * i


@njit(cache=True, inline="always")
def terms(q, qd, packed, M, h, Ja):
    """Fill M (4x4), h = G - C (4,) and the rods' attachment Jacobian Ja (4x4: thigh rod, shank rod) in place.

    Closed form for the cart + three segments, unrolled so that the hot loop
    stays in registers. For segment i the COM Jacobian column of an earlier
    segment j is a_j = dR(q_j) (0, -L_j) = (-L_j c_j, L_j s_j), its own column
    b_i = dR(q_i) (rx_i, ry_i); the velocity-product acceleration is
    -sum R(-q_j) v_j q_j'^2.
    """
    g = packed[GRAVITY]
    m1, I1, L1, x1, y1 = packed[1], packed[2], packed[3], packed[4], packed[5]
    m2, I2, L2, x2, y2 = packed[6], packed[7], packed[8], packed[9], packed[10]
    m3, I3, x3, y3 = packed[11], packed[12], packed[14], packed[15]
    c1 = np.cos(q[1])
    s1 = np.sin(q[1])
    c2 = np.cos(q[2])
    s2 = np.sin(q[2])
    c3 = np.cos(q[3])
    s3 = np.sin(q[3])
    w1 = qd[1] * qd[1]
    w2 = qd[2] * qd[2]
    w3 = qd[3] * qd[3]
    # link columns (thigh, shank) and COM columns (all three)
    a1x, a1y = -L1 * c1, L1 * s1
    a2x, a2y = -L2 * c2, L2 * s2
    b1x, b1y = -x1 * s1 + y1 * c1, -x1 * c1 - y1 * s1
    b2x, b2y = -x2 * s2 + y2 * c2, -x2 * c2 - y2 * s2
    b3x, b3y = -x3 * s3 + y3 * c3, -x3 * c3 - y3 * s3
    # R(-q) v = (-b_y, b_x) for a column b = dR v; sum R v q'^2 = -(velocity-product acceleration)
    acc1x = -b1y * w1
    acc1y = b1x * w1
    l1x = -a1y * w1
    l1y = a1x * w1
    acc2x = l1x - b2y * w2
    acc2y = l1y + b2x * w2
    l2x = l1x - a2y * w2
    l2y = l1y + a2x * w2
    acc3x = l2x - b3y * w3
    acc3y = l2y + b3x * w3
    # COM forces m (gravity - velocity-product acceleration)
    f1x = m1 * acc1x
    f1y = m1 * (-g + acc1y)
    f2x = m2 * acc2x
    f2y = m2 * (-g + acc2y)
    f3x = m3 * acc3x
    f3y = m3 * (-g + acc3y)
    m23 = m2 + m3
    M[0, 0] = packed[CART_MASS] + m1 + m23
    M[0, 1] = m1 * b1x + m23 * a1x
    M[0, 2] = m2 * b2x + m3 * a2x
    M[0, 3] = m3 * b3x
    M[1, 1] = I1 + m1 * (b1x * b1x + b1y * b1y) + m23 * (a1x * a1x + a1y * a1y)
    a1a2 = a1x * a2x + a1y * a2y
    M[1, 2] = m2 * (a1x * b2x + a1y * b2y) + m3 * a1a2
    M[1, 3] = m3 * (a1x * b3x + a1y * b3y)
    M[2, 2] = I2 + m2 * (b2x * b2x + b2y * b2y) + m3 * (a2x * a2x + a2y * a2y)
    M[2, 3] = m3 * (a2x * b3x + a2y * b3y)
    M[3, 3] = I3 + m3 * (b3x * b3x + b3y * b3y)
    M[1, 0] = M[0, 1]
    M[2, 0] = M[0, 2]
    M[3, 0] = M[0, 3]
    M[2, 1] = M[1, 2]
    M[3, 1] = M[1, 3]
    M[3, 2] = M[2, 3]
    h[0] = f1x + f2x + f3x
    h[1] = b1x * f1x + b1y * f1y + a1x * (f2x + f3x) + a1y * (f2y + f3y)
    h[2] = b2x * f2x + b2y * f2y + a2x * f3x + a2y * f3y
    h[3] = b3x * f3x + b3y * f3y
    d = packed[ATTACHMENT]
    Ja[0, 0] = 1.0
    Ja[1, 0] = 0.0
    Ja[0, 1] = -d * c1
    Ja[1, 1] = d * s1
    for a in range(2, 4):
        Ja[0, a] = 0.0
        Ja[1, a] = 0.0
    # the shank rod's point: the knee (a1 of the thigh) and ds along the shank
    ds = packed[SHANK_ATTACHMENT]
    Ja[2, 0] = 1.0
    Ja[3, 0] = 0.0
    Ja[2, 1] = a1x
    Ja[3, 1] = a1y
    Ja[2, 2] = -ds * c2
    Ja[3, 2] = ds * s2
    Ja[2, 3] = 0.0
    Ja[3, 3] = 0.0


@njit(cache=True, inline="always")
def solve4(M, r, out):
    """Solve the SPD 4x4 system M out = r by Cholesky (M is overwritten)."""
    for j in range(4):
        acc = M[j, j]
        for k in range(j):
            acc -= M[j, k] * M[j, k]
        d = np.sqrt(acc)
        M[j, j] = d
        for i in range(j + 1, 4):
            acc = M[i, j]
            for k in range(j):
                acc -= M[i, k] * M[j, k]
            M[i, j] = acc / d
    for i in range(4):
        acc = r[i]
        for k in range(i):
            acc -= M[i, k] * out[k]
        out[i] = acc / M[i, i]
    for i in range(3, -1, -1):
        acc = out[i]
        for k in range(i + 1, 4):
            acc -= M[k, i] * out[k]
        out[i] = acc / M[i, i]


@njit(cache=True)
def terms_batch(q, qd, packed):
    """M (n,4,4), h (n,4), Ja (n,4,4) for n states."""
    n = q.shape[0]
    M = np.empty((n, 4, 4))
    h = np.empty((n, 4))
    Ja = np.empty((n, 4, 4))
    for k in range(n):
        terms(q[k], qd[k], packed, M[k], h[k], Ja[k])
    return M, h, Ja


def _add_couplings(T, couplings, dh, dk, da):
    """Subtract the inter-joint stiffness torques from the joint torques T (3,): couplings (2,) = (K_hip_knee,
    K_knee_ankle) in N m/rad, dh, dk, da the hip, knee and ankle angle deviations (rad).

    Compiled by the type of ``couplings`` (:func:`_add_couplings_typed`): without couplings (None) it compiles to
    nothing, so the six-parameter path runs the plain diagonal feedback's instructions, no more. (Measured on
    the RK4 loop: a run-time branch on whether there are couplings made it about 40 % slower, always subtracting
    couplings of 0 about 2 %.)
    """
    T[0] -= couplings[0] * dk
    T[1] -= couplings[0] * dh + couplings[1] * da
    T[2] -= couplings[1] * dk


@overload(_add_couplings, inline="always")
def _add_couplings_typed(T, couplings, dh, dk, da):
    """:func:`_add_couplings` for numba: a no-op for None, else the three subtractions."""
    if isinstance(couplings, (types.NoneType, types.Omitted)):
        return lambda T, couplings, dh, dk, da: None

    def impl(T, couplings, dh, dk, da):
        T[0] -= couplings[0] * dk
        T[1] -= couplings[0] * dh + couplings[1] * da
        T[2] -= couplings[1] * dk

    return impl


def _coupling_row(couplings, b):
    """Row b of the couplings (B, 2), or None without them (compiled by type, :func:`_coupling_row_typed`)."""
    return None if couplings is None else couplings[b]


@overload(_coupling_row, inline="always")
def _coupling_row_typed(couplings, b):
    """:func:`_coupling_row` for numba: None for None, else the row."""
    if isinstance(couplings, (types.NoneType, types.Omitted)):
        return lambda couplings, b: None
    return lambda couplings, b: couplings[b]


@njit(cache=True, inline="always")
def feedback_torques(e, ed, dpel, dpeld, p, T, couplings=None):
    """Joint torques T = -K dtheta - D dtheta_dot (hip, knee, ankle) from deviations.

    e, ed: deviation of the model state from the reference (4,); dpel, dpeld:
    pelvis angle deviation (rad, rad/s); p = (K_hip, D_hip, K_knee, D_knee,
    K_ankle, D_ankle). ``couplings`` (2,): the inter-joint stiffnesses (K_hip_knee, K_knee_ankle) in N m/rad,
    off the diagonal of a symmetric stiffness matrix (joint angles flexion and dorsiflexion positive)::

        T_hip   = -K_hip dth_hip - D_hip dth_hip' - K_hip_knee dth_knee
        T_knee  = -K_knee dth_knee - D_knee dth_knee' - (K_hip_knee dth_hip + K_knee_ankle dth_ankle)
        T_ankle = -K_ankle dth_ankle - D_ankle dth_ankle' - K_knee_ankle dth_knee

    None (the default): the diagonal terms alone, compiled without the coupling terms.
    """
    dh = dpel - e[1]
    dhd = dpeld - ed[1]
    dk = e[2] - e[1]
    dkd = ed[2] - ed[1]
    da = e[2] - e[3]
    dad = ed[2] - ed[3]
    T[0] = -p[0] * dh - p[1] * dhd
    T[1] = -p[2] * dk - p[3] * dkd
    T[2] = -p[4] * da - p[5] * dad
    _add_couplings(T, couplings, dh, dk, da)


@njit(cache=True, inline="always")
def _deviation_rhs(k, e, ed, p, packed, ref_q, ref_qd, ref_qdd, w, fp, fs, dpel, M, h, Ja, rhs, T, qdd, state):
    """Acceleration of the deviation e = q - q_ref at stage index k, rod forces fp (2,) at the thigh and fs (2,)
    at the shank; p = (impedance (6,), inter-joint stiffnesses (2,) or None), as :func:`feedback_torques` takes
    them.

    Fills qdd; ``state`` (2, 4) is work space.
    """
    q = state[0]
    qd = state[1]
    for a in range(4):
        q[a] = ref_q[k, a] + e[a]
        qd[a] = ref_qd[k, a] + ed[a]
    terms(q, qd, packed, M, h, Ja)
    feedback_torques(e, ed, dpel[k, 0], dpel[k, 1], p[0], T, p[1])
    rhs[0] = h[0] + w[k, 0] + Ja[0, 0] * fp[0] + Ja[1, 0] * fp[1] + Ja[2, 0] * fs[0] + Ja[3, 0] * fs[1]
    rhs[1] = h[1] + w[k, 1] - T[0] - T[1] + Ja[0, 1] * fp[0] + Ja[1, 1] * fp[1] + Ja[2, 1] * fs[0] + Ja[3, 1] * fs[1]
    rhs[2] = h[2] + w[k, 2] + T[1] + T[2] + Ja[0, 2] * fp[0] + Ja[1, 2] * fp[1] + Ja[2, 2] * fs[0] + Ja[3, 2] * fs[1]
    rhs[3] = h[3] + w[k, 3] - T[2] + Ja[0, 3] * fp[0] + Ja[1, 3] * fp[1] + Ja[2, 3] * fs[0] + Ja[3, 3] * fs[1]
    solve4(M, rhs, qdd)
    for a in range(4):
        qdd[a] -= ref_qdd[k, a]


@njit(cache=True)
def simulate_deviation_batch(P, packed, ref_q, ref_qd, ref_qdd, w, fp, fs, dpel, e0, ed0, dt, n_sub, n_out, C=None):
    """RK4 of the deviation dynamics for a batch of parameter sets.

    The model trajectory is q = q_ref + e with
    M(q) q'' = h(q, q') + w + u_fb + Ja(q)^T F_p, w = u_ff - Ja(q_ref)^T F_u (F: both rods' forces),
    so e stays exactly 0 without perturbation (q_ref'' is subtracted).

    P: (B, 6) parameter sets in the order of ``PARAMETERS``; C: None, or (B, 2) their inter-joint stiffnesses
    K_hip_knee and K_knee_ankle (:func:`feedback_torques`; a separate compiled variant: without C the loop holds
    no coupling term); stage arrays (ref_q, ref_qd, ref_qdd, w: (2 N + 1, 4);
    dpel: (2 N + 1, 2)) sampled every dt / 2 from the window start; fp (N, 4, 2)
    the thigh rod's force at the four stages of each of the N steps, fs (N, 4, 2) the shank rod's; e0, ed0: (4,)
    initial deviation; n_sub RK4 steps per output sample.
    Returns E (B, n_out, 4) deviations and Ed (B, n_out, 4) their rates at the
    output samples (sample 0 = initial state).
    """
    B = P.shape[0]
    E = np.empty((B, n_out, 4))
    Ed = np.empty((B, n_out, 4))
    M = np.empty((4, 4))
    h = np.empty(4)
    Ja = np.empty((4, 4))
    rhs = np.empty(4)
    T = np.empty(3)
    e = np.empty(4)
    ed = np.empty(4)
    et = np.empty(4)
    edt = np.empty(4)
    k1 = np.empty(4)
    k2 = np.empty(4)
    k3 = np.empty(4)
    k4 = np.empty(4)
    v2 = np.empty(4)
    v3 = np.empty(4)
    state = np.empty((2, 4))
    for b in range(B):
        p = (P[b], _coupling_row(C, b))
        for a in range(4):
            e[a] = e0[a]
            ed[a] = ed0[a]
            E[b, 0, a] = e[a]
            Ed[b, 0, a] = ed[a]
        st = 0
        for o in range(1, n_out):
            for _ in range(n_sub):
                k, kh, ke, fpk, fsk = 2 * st, 2 * st + 1, 2 * st + 2, fp[st], fs[st]
                _deviation_rhs(
                    k, e, ed, p, packed, ref_q, ref_qd, ref_qdd, w, fpk[0], fsk[0], dpel, M, h, Ja, rhs, T, k1, state
                )
                for a in range(4):
                    et[a] = e[a] + 0.5 * dt * ed[a]
                    edt[a] = ed[a] + 0.5 * dt * k1[a]
                _deviation_rhs(
                    kh, et, edt, p, packed, ref_q, ref_qd, ref_qdd, w, fpk[1], fsk[1], dpel, M, h, Ja, rhs, T, k2, state
                )
                for a in range(4):
                    v2[a] = edt[a]
                for a in range(4):
                    et[a] = e[a] + 0.5 * dt * v2[a]
                    edt[a] = ed[a] + 0.5 * dt * k2[a]
                _deviation_rhs(
                    kh, et, edt, p, packed, ref_q, ref_qd, ref_qdd, w, fpk[2], fsk[2], dpel, M, h, Ja, rhs, T, k3, state
                )
                for a in range(4):
                    v3[a] = edt[a]
                for a in range(4):
                    et[a] = e[a] + dt * v3[a]
                    edt[a] = ed[a] + dt * k3[a]
                _deviation_rhs(
                    ke, et, edt, p, packed, ref_q, ref_qd, ref_qdd, w, fpk[3], fsk[3], dpel, M, h, Ja, rhs, T, k4, state
                )
                for a in range(4):
                    e[a] += dt / 6.0 * (ed[a] + 2.0 * v2[a] + 2.0 * v3[a] + edt[a])
                    ed[a] += dt / 6.0 * (k1[a] + 2.0 * k2[a] + 2.0 * k3[a] + k4[a])
                st += 1
            for a in range(4):
                E[b, o, a] = e[a]
                Ed[b, o, a] = ed[a]
    return E, Ed
