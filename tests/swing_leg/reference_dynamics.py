"""The swing-leg model's terms one by one and a reference forward simulation, for checking the compiled kernels
(:mod:`loper_analysis.swing_leg.kernels`) and the equations against OpenSim's model of the same mechanism.

The terms of ``M(q) q'' = -C(q, q') + G(q) + u + Ja(q)^T F`` (``docs/swing_leg_model.md``): :func:`mass_matrix`,
:func:`coriolis_forces`, :func:`gravity_forces`, :func:`attachment_jacobian`; the positions of the segments'
centres of mass and of the rod attachment; :func:`forward_dynamics`; the generalised forces of joint torques; and
:func:`simulate`, SciPy's DOP853 (the reference integrator the identification's fixed-step RK4 is checked against).
Inputs are checked as :mod:`loper_analysis.swing_leg.dynamics` checks its own.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.checks import finite_rows
from loper_analysis.errors import LoperInputError
from loper_analysis.swing_leg import kernels
from loper_analysis.swing_leg.dynamics import SegmentParameters, _checked_terms, _force, _out, _same_rows

__all__ = [
    "attachment_jacobian",
    "attachment_position",
    "shank_attachment_jacobian",
    "shank_attachment_position",
    "coriolis_forces",
    "forward_dynamics",
    "generalized_joint_forces",
    "gravity_forces",
    "mass_matrix",
    "segment_com_positions",
    "simulate",
]


def mass_matrix(q, params: SegmentParameters) -> np.ndarray:
    """Mass matrix M(q): (4, 4) for one state or (n, 4, 4); kg and kg m^2 (mixed units)."""
    q2, single = finite_rows("q", q, 4)
    M, _, _ = kernels.terms_batch(q2, np.zeros_like(q2), params.packed)
    return _out(M, single)


def coriolis_forces(q, qd, params: SegmentParameters) -> np.ndarray:
    """C(q, q') (n, 4): velocity-product forces, entering as -C (N, N m)."""
    q2, single = finite_rows("q", q, 4)
    qd2, _ = finite_rows("qd", qd, 4)
    _same_rows(("q", q2), ("qd", qd2))
    no_gravity = params.packed.copy()
    no_gravity[kernels.GRAVITY] = 0.0
    _, h, _ = kernels.terms_batch(q2, qd2, no_gravity)
    return _out(-h, single)


def gravity_forces(q, params: SegmentParameters) -> np.ndarray:
    """G(q) (n, 4): generalised gravity forces, entering as +G (N, N m)."""
    q2, single = finite_rows("q", q, 4)
    _, h, _ = kernels.terms_batch(q2, np.zeros_like(q2), params.packed)
    return _out(h, single)


def attachment_jacobian(q, params: SegmentParameters) -> np.ndarray:
    """Jacobian of the thigh rod's attachment point, (2, 4) or (n, 2, 4) (m/m, m/rad)."""
    q2, single = finite_rows("q", q, 4)
    _, _, Ja = kernels.terms_batch(q2, np.zeros_like(q2), params.packed)
    return _out(Ja[:, :2], single)


def shank_attachment_jacobian(q, params: SegmentParameters) -> np.ndarray:
    """Jacobian of the shank rod's attachment point, (2, 4) or (n, 2, 4) (m/m, m/rad)."""
    q2, single = finite_rows("q", q, 4)
    _, _, Ja = kernels.terms_batch(q2, np.zeros_like(q2), params.packed)
    return _out(Ja[:, 2:], single)


def _rot(q: np.ndarray, v: tuple[float, float]) -> np.ndarray:
    """R(-q) v for an array of angles: (n, 2)."""
    c, s = np.cos(q), np.sin(q)
    return np.stack([v[0] * c + v[1] * s, -v[0] * s + v[1] * c], axis=-1)


def segment_com_positions(q, params: SegmentParameters) -> np.ndarray:
    """World positions of the thigh, shank and foot COM, (n, 3, 2) in m (hip at (x, 0))."""
    q2, single = finite_rows("q", q, 4)
    base = np.stack([q2[:, 0], np.zeros(len(q2))], axis=-1)
    out = np.empty((len(q2), 3, 2))
    for i in range(3):
        out[:, i] = base + _rot(q2[:, 1 + i], (params.com_x_m[i], params.com_y_m[i]))
        base = base + _rot(q2[:, 1 + i], (0.0, -params.length_m[i]))
    return _out(out, single)


def attachment_position(q, params: SegmentParameters) -> np.ndarray:
    """World position (n, 2) of the rod attachment point on the thigh (m)."""
    q2, single = finite_rows("q", q, 4)
    pos = np.stack([q2[:, 0], np.zeros(len(q2))], axis=-1) + _rot(q2[:, 1], (0.0, -params.attachment_m))
    return _out(pos, single)


def shank_attachment_position(q, params: SegmentParameters) -> np.ndarray:
    """World position (n, 2) of the shank rod's attachment point (m)."""
    q2, single = finite_rows("q", q, 4)
    knee = np.stack([q2[:, 0], np.zeros(len(q2))], axis=-1) + _rot(q2[:, 1], (0.0, -params.length_m[0]))
    return _out(knee + _rot(q2[:, 2], (0.0, -params.shank_attachment_m)), single)


def forward_dynamics(q, qd, u, params: SegmentParameters, force_n=None, shank_force_n=None) -> np.ndarray:
    """Accelerations q'' (n, 4) from M q'' = -C + G + u + Ja^T F + Js^T F_s."""
    u2, F, M, h, Ja, single = _checked_terms(q, qd, "u", u, params, force_n)
    rhs = h + u2 + np.einsum("nji,nj->ni", Ja[:, :2], F)
    if shank_force_n is not None:
        rhs = rhs + np.einsum("nji,nj->ni", Ja[:, 2:], _force(shank_force_n, len(u2)))
    return _out(np.linalg.solve(M, rhs[..., None])[..., 0], single)


def generalized_joint_forces(torques_nm) -> np.ndarray:
    """Generalised forces (n, 4) of hip, knee, ankle joint torques (n, 3) in N m."""
    T, single = finite_rows("torques_nm", torques_nm, 3)
    u = np.stack([np.zeros(len(T)), -T[:, 0] - T[:, 1], T[:, 1] + T[:, 2], -T[:, 2]], axis=-1)
    return _out(u, single)


def _interp_columns(t: float, time_s: np.ndarray, values: np.ndarray) -> np.ndarray:
    return np.array([np.interp(t, time_s, values[:, j]) for j in range(values.shape[1])])


def simulate(
    time_s,
    q0,
    qd0,
    params: SegmentParameters,
    *,
    u_ff=None,
    force_n=None,
    shank_force_n=None,
    impedance=None,
    reference_joint_angles_rad=None,
    reference_joint_velocities_rad_s=None,
    pelvis_angle_rad=None,
    pelvis_velocity_rad_s=None,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> tuple[np.ndarray, np.ndarray]:
    """Forward simulation with SciPy's DOP853 (the reference integrator).

    Inputs sampled at ``time_s`` (n,) are linearly interpolated: ``u_ff`` (n, 4),
    ``force_n`` (n, 2) at the thigh rod's attachment point, ``shank_force_n`` (n, 2) at the shank rod's, pelvis
    angle and rate (n,).
    With ``impedance = (K_hip, D_hip, K_knee, D_knee, K_ankle, D_ankle)`` the
    joints get ``T = -K (theta - theta_ref) - D (theta' - theta_ref')`` with
    the reference angles/rates (n, 3) (zero when omitted).

    Returns q (n, 4) and q' (n, 4) at ``time_s``.
    """
    from scipy.integrate import solve_ivp  # here: scipy.integrate costs ~0.4 s, and fits never integrate with it

    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or len(t) < 2 or not np.all(np.isfinite(t)) or np.any(np.diff(t) <= 0):
        raise LoperInputError("time_s must be a finite, strictly increasing 1-D array of >= 2 samples")
    n = len(t)
    x0, _ = finite_rows("q0", q0, 4)
    v0, _ = finite_rows("qd0", qd0, 4)
    uff = np.zeros((n, 4)) if u_ff is None else finite_rows("u_ff", u_ff, 4)[0]
    F = np.hstack([_force(force_n, n), _force(shank_force_n, n)])
    _same_rows(("time_s", t[:, None]), ("u_ff", uff), ("force_n", F))

    def col(name, value, width):
        if value is None:
            return np.zeros((n, width))
        a = np.asarray(value, dtype=float)
        a2, _ = finite_rows(name, a.reshape(n, width) if a.ndim == 1 and width == 1 else a, width)
        _same_rows(("time_s", t[:, None]), (name, a2))
        return a2

    pel = col("pelvis_angle_rad", pelvis_angle_rad, 1)
    peld = col("pelvis_velocity_rad_s", pelvis_velocity_rad_s, 1)
    th_ref = col("reference_joint_angles_rad", reference_joint_angles_rad, 3)
    thd_ref = col("reference_joint_velocities_rad_s", reference_joint_velocities_rad_s, 3)
    if impedance is not None:
        p = np.asarray(impedance, dtype=float)
        if p.shape != (6,) or not np.all(np.isfinite(p)):
            raise LoperInputError(f"impedance must be 6 finite values (K, D per joint), got {p}")
    packed = params.packed
    M = np.empty((4, 4))
    h = np.empty(4)
    Ja = np.empty((4, 4))
    inputs = np.hstack([uff, F, pel, peld, th_ref, thd_ref])

    def rhs(time, y):
        q, qd = y[:4], y[4:]
        z = _interp_columns(time, t, inputs)
        kernels.terms(q, qd, packed, M, h, Ja)
        r = h + z[:4] + Ja.T @ z[4:8]
        if impedance is not None:
            pel_t, peld_t = z[8], z[9]
            th = np.array([pel_t - q[1], q[2] - q[1], q[2] - q[3]])
            thd = np.array([peld_t - qd[1], qd[2] - qd[1], qd[2] - qd[3]])
            T = -p[0::2] * (th - z[10:13]) - p[1::2] * (thd - z[13:16])
            r = r + generalized_joint_forces(T)
        return np.concatenate([qd, np.linalg.solve(M, r)])

    # integrate sample to sample so the kinks of the interpolated inputs are honoured
    y = np.concatenate([x0[0], v0[0]])
    out = np.empty((n, 8))
    out[0] = y
    for k in range(n - 1):
        sol = solve_ivp(rhs, (t[k], t[k + 1]), y, method="DOP853", rtol=rtol, atol=atol)
        if not sol.success:
            raise RuntimeError(f"forward simulation failed at t = {t[k]} s: {sol.message}")
        y = sol.y[:, -1]
        out[k + 1] = y
    return out[:, :4], out[:, 4:]
