"""Joint impedance (K, D per joint) from a perturbed and an unperturbed stride.

Method (DESIGN.md section 5):

1. The unperturbed measured coordinates ``q_u`` (cubic spline through the
   samples) are the reference; ``u_ff`` is their inverse dynamics, which
   absorbs the minimal-impedance device force ``F_u``.
2. The perturbed model is driven by ``u_ff + u_fb + Ja(q)^T F_p - Ja(q_u)^T F_u``
   with the impedance feedback ``T = -K dtheta - D dtheta'`` about the
   unperturbed joint angles, from the measured state at window start.
   We integrate the *deviation* ``e = q_model - q_u`` (fixed-step RK4,
   ``n_substeps`` steps per sample): this is the study's "simulate perturbed
   and unperturbed and subtract", with the unperturbed simulation exact by
   construction (without perturbation e stays 0), so no integration error of
   the unperturbed path leaks into the fit.
3. Prediction error ``PE = (theta_p - theta_u)_measured - (theta_p - theta_u)_model``
   on hip, knee and ankle angles over the window (25 ms before to 250 ms
   after onset by default).
4. ``min sum PE^2`` with K in [0, 200] N m/rad, D in [0, 10] N m s/rad: random
   starts drawn uniformly inside the bounds are iterated *together* by a
   bound-constrained Levenberg-Marquardt whose residuals and forward-difference
   Jacobians for all starts come from one compiled batch simulation; the best
   start is then polished by ``scipy.optimize.least_squares`` (trust-region
   reflective), whose status is the fit's status.

Beyond the study: 95 % confidence intervals from the Jacobian at the optimum
(``cov = s^2 (J^T J)^-1 + A J^T G S0 G^T J A``, ``A = (J^T J)^-1``,
``s^2 = SSR / (m - 6)``, ``G`` the sensitivity to the initial state and ``S0``
its covariance from the pre-onset fit; Student t quantile) and the parameter
correlation matrix. A wide CI or a correlation near +-1 flags a
parameter the data cannot identify (typically the ankle).

Also beyond the study: the stride-to-stride deviation. The prediction error
of a mean response is not white: the matched unperturbed stride differs from
the perturbed stride's own unperturbed course by a smooth deviation that the
25 ms pre-onset match cannot remove, and with a dozen strides its average
still biases D. Unperturbed strides paired by the same rule (*null pairs*)
show that error without a response (:func:`null_pair_errors`). Its few
dominant shapes (principal components) are projected out of the prediction
error (:func:`nuisance_projection`, ``PreparedWindow.residual_weight``) - the
same as fitting their amplitudes as nuisance parameters - and the CI come
from the null pairs' covariance by the sandwich ``cov = M C M^T``,
``M = (W J)^+ W``, ``C = PreparedWindow.noise_cov``.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import least_squares
from scipy.stats import t as student_t

from . import _kernels
from .constants import JOINTS, PARAMETERS
from .dynamics import SegmentParameters, _states, inverse_dynamics, joint_angles
from .errors import LoperInputError

__all__ = [
    "DEFAULT_LOWER",
    "DEFAULT_UPPER",
    "PreparedWindow",
    "ImpedanceFit",
    "prepare_window",
    "simulate_response",
    "prediction_error",
    "identify_impedance",
    "variance_accounted_for",
    "response_jacobian",
    "null_pair_errors",
    "nuisance_projection",
]

#: Default bounds (K N m/rad, D N m s/rad), order of :data:`PARAMETERS`.
DEFAULT_LOWER = np.zeros(6)
DEFAULT_UPPER = np.array([200.0, 10.0, 200.0, 10.0, 200.0, 10.0])
_MU0, _MU_DOWN, _MU_UP = 1e-2, 10.0, 10.0


@dataclass(frozen=True)
class PreparedWindow:
    """Everything the compiled simulation needs for one perturbed/unperturbed pair.

    Stage arrays are sampled every ``dt_s / 2`` from the window start
    (``2 * n_steps + 1`` rows). ``measured`` (n_out, 3) is the measured
    perturbed-minus-unperturbed joint angle difference (rad) at the window's
    samples ``time_s`` (n_out,). ``initial_state_cov`` (8, 8) is the covariance
    of ``[e0, ed0]`` from the scatter of the pre-onset differences about their
    polynomial (zero for noise-free data). Optional, m = 3 n_out values
    (samples, then hip/knee/ankle): ``residual_weight`` (m, m) multiplies the
    prediction error before it is squared (:func:`nuisance_projection`);
    ``noise_cov`` (m, m) is the covariance of the prediction error at the true
    impedance (rad^2, e.g. from :func:`null_pair_errors` divided by the number
    of averaged pairs), from which the CI are taken when given.
    """

    params: SegmentParameters
    time_s: np.ndarray
    measured: np.ndarray
    ref_q: np.ndarray
    ref_qd: np.ndarray
    ref_qdd: np.ndarray
    w: np.ndarray
    force_p: np.ndarray
    dpelvis: np.ndarray
    e0: np.ndarray
    ed0: np.ndarray
    dt_s: float
    n_substeps: int
    initial_state_cov: np.ndarray = field(default_factory=lambda: np.zeros((8, 8)))
    onset_s: float = 0.0
    initial_state_span_s: float = 0.1
    initial_state_degree: int = 1
    noise_cov: np.ndarray | None = None
    residual_weight: np.ndarray | None = None

    @property
    def n_samples(self) -> int:
        return len(self.time_s)


@dataclass
class ImpedanceFit:
    """Result of :func:`identify_impedance` (parameter order :data:`PARAMETERS`)."""

    estimate: np.ndarray
    cost: float
    ci95_low: np.ndarray
    ci95_high: np.ndarray
    correlation: np.ndarray
    vaf_pct: np.ndarray
    success: bool
    message: str
    n_starts: int
    n_starts_at_best: int
    n_simulations: int
    starts: np.ndarray = field(repr=False)
    start_estimates: np.ndarray = field(repr=False)
    start_costs: np.ndarray = field(repr=False)
    time_s: np.ndarray = field(repr=False)
    measured: np.ndarray = field(repr=False)
    model: np.ndarray = field(repr=False)

    def as_dict(self) -> dict[str, float]:
        """Flat record: estimates, CI bounds, VAF per joint, cost and diagnostics."""
        out: dict = {}
        for i, name in enumerate(PARAMETERS):
            out[name] = float(self.estimate[i])
            out[f"{name}_ci95_low"] = float(self.ci95_low[i])
            out[f"{name}_ci95_high"] = float(self.ci95_high[i])
        for j, joint in enumerate(JOINTS):
            out[f"vaf_{joint}_pct"] = float(self.vaf_pct[j])
        out.update(
            cost_rad2=self.cost,
            success=self.success,
            message=self.message,
            n_starts=self.n_starts,
            n_starts_at_best=self.n_starts_at_best,
            n_simulations=self.n_simulations,
        )
        return out


# ---------------------------------------------------------------- preparation


def _column(name: str, value, n: int, width: int) -> np.ndarray:
    if value is None:
        return np.zeros((n, width))
    a = np.asarray(value, dtype=float)
    if width == 1 and a.ndim == 1:
        a = a[:, None]
    a2, _ = _states(name, a, width)
    if a2.shape[0] != n:
        raise LoperInputError(f"{name} has {a2.shape[0]} samples, expected {n} like time_s")
    return a2


def prepare_window(
    time_s,
    q_unperturbed,
    q_perturbed,
    params: SegmentParameters,
    onset_s: float,
    *,
    force_unperturbed_n=None,
    force_perturbed_n=None,
    pelvis_angle_unperturbed_rad=None,
    pelvis_angle_perturbed_rad=None,
    window_before_s: float = 0.025,
    window_after_s: float = 0.25,
    n_substeps: int = 2,
    reference_cutoff_hz: float | None = None,
    q_reference=None,
    initial_state_span_s: float = 0.1,
    initial_state_degree: int = 1,
) -> PreparedWindow:
    """Check the inputs of one fit and precompute reference, inputs and initial state.

    Parameters
    ----------
    time_s : (n,) uniformly sampled time (s); the window must lie inside it.
    q_unperturbed, q_perturbed : (n, 4) measured coordinates [x (m), thigh,
        shank, foot (rad)] of the unperturbed and the perturbed stride,
        aligned so that the onset is at ``onset_s`` in both.
    force_unperturbed_n, force_perturbed_n : (n, 2) rod force (N, world x/y)
        at the attachment point; zero when omitted.
    pelvis_angle_*_rad : (n,) pelvis angle (rad); zero when omitted.
    window_before_s, window_after_s : window around the onset (s).
    n_substeps : RK4 steps per sample (integer >= 1).
    reference_cutoff_hz : if given, the unperturbed coordinates are low-pass
        filtered (2nd-order zero-phase Butterworth) before they serve as the
        reference whose derivatives give ``u_ff``; the measured differences
        in the prediction error stay unfiltered.
    q_reference : (n, 4) optional smooth reference coordinates for ``u_ff``
        and the feedback operating point (e.g. the mean of many unperturbed
        strides); ``q_unperturbed`` when omitted.
    initial_state_span_s, initial_state_degree : the initial deviation and
        its rate at window start come from a least-squares polynomial of this
        degree through the perturbed-minus-unperturbed coordinates over the
        last ``initial_state_span_s`` before the onset, when the perturbation
        has not yet acted (robust to measurement noise; exact for smooth data).

    Raises
    ------
    LoperInputError
        Non-finite or wrongly shaped inputs, non-uniform time, a window
        outside the data.
    """
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or len(t) < 4:
        raise LoperInputError(f"time_s must be 1-D with >= 4 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise LoperInputError(f"time_s is not finite at sample {int(np.argmax(~np.isfinite(t)))}")
    dts = np.diff(t)
    dt = float(np.mean(dts))
    if dt <= 0 or np.max(np.abs(dts - dt)) > 1e-6 * dt:
        i = int(np.argmax(np.abs(dts - dt)))
        raise LoperInputError(f"time_s must be uniformly increasing; step at sample {i} is {dts[i]} s, mean {dt} s")
    n = len(t)
    qu = _column("q_unperturbed", q_unperturbed, n, 4)
    qp = _column("q_perturbed", q_perturbed, n, 4)
    fu = _column("force_unperturbed_n", force_unperturbed_n, n, 2)
    fpm = _column("force_perturbed_n", force_perturbed_n, n, 2)
    pu = _column("pelvis_angle_unperturbed_rad", pelvis_angle_unperturbed_rad, n, 1)[:, 0]
    pp = _column("pelvis_angle_perturbed_rad", pelvis_angle_perturbed_rad, n, 1)[:, 0]
    for name, v in (("onset_s", onset_s), ("window_before_s", window_before_s), ("window_after_s", window_after_s)):
        if not np.isfinite(v):
            raise LoperInputError(f"{name} must be finite, got {v}")
    if window_before_s < 0 or window_after_s <= 0:
        raise LoperInputError(
            f"window must have window_before_s >= 0 and window_after_s > 0, got {window_before_s}, {window_after_s}"
        )
    if int(n_substeps) != n_substeps or n_substeps < 1:
        raise LoperInputError(f"n_substeps must be an integer >= 1, got {n_substeps}")
    n_substeps = int(n_substeps)
    tol = 1e-9 * dt
    i0 = int(np.ceil((onset_s - window_before_s - t[0]) / dt - 1e-9))
    i1 = int(np.floor((onset_s + window_after_s - t[0]) / dt + 1e-9))
    if onset_s - window_before_s < t[0] - tol or i1 > n - 1 or i0 < 0:
        raise LoperInputError(
            f"window {onset_s - window_before_s:.4f} .. {onset_s + window_after_s:.4f} s "
            f"is longer than the data ({t[0]:.4f} .. {t[-1]:.4f} s)"
        )
    if i1 - i0 < 3:
        raise LoperInputError(f"window holds only {i1 - i0 + 1} samples; need >= 4")

    # reference: cubic spline of the unperturbed coordinates, at RK4 stage times
    h = dt / n_substeps
    n_steps = (i1 - i0) * n_substeps
    ts = t[i0] + 0.5 * h * np.arange(2 * n_steps + 1)
    q_ref = qu if q_reference is None else _column("q_reference", q_reference, n, 4)
    if reference_cutoff_hz is not None:
        nyq = 0.5 / dt
        if not 0 < reference_cutoff_hz < nyq:
            raise LoperInputError(f"reference_cutoff_hz must lie in 0 .. {nyq} Hz, got {reference_cutoff_hz}")
        from scipy.signal import butter, filtfilt  # only here: scipy.signal costs ~1 s to import

        b, a = butter(2, reference_cutoff_hz / nyq)
        q_ref = filtfilt(b, a, q_ref, axis=0)
    spline = CubicSpline(t, q_ref, axis=0)
    ref_q = spline(ts)
    ref_qd = spline(ts, 1)
    ref_qdd = spline(ts, 2)
    force_u = np.stack([np.interp(ts, t, fu[:, j]) for j in range(2)], axis=-1)
    force_p = np.stack([np.interp(ts, t, fpm[:, j]) for j in range(2)], axis=-1)
    # u_ff - Ja(q_u)^T F_u = inverse dynamics with the unperturbed force
    w = inverse_dynamics(ref_q, ref_qd, ref_qdd, params, force_u)
    dpel_spline = CubicSpline(t, pp - pu)
    dpel = np.stack([dpel_spline(ts), dpel_spline(ts, 1)], axis=-1)
    # initial deviation: polynomial through the pre-onset differences, taken
    # relative to the reference actually simulated
    sel = (t >= onset_s - initial_state_span_s - tol) & (t <= onset_s + tol)
    if int(initial_state_degree) != initial_state_degree or initial_state_degree < 0:
        raise LoperInputError(f"initial_state_degree must be an integer >= 0, got {initial_state_degree}")
    if sel.sum() < initial_state_degree + 1 or onset_s - initial_state_span_s < t[0] - tol:
        raise LoperInputError(
            f"initial state needs data from {onset_s - initial_state_span_s:.4f} s "
            f"(initial_state_span_s = {initial_state_span_s}) with >= {initial_state_degree + 1} samples; "
            f"data start at {t[0]:.4f} s"
        )
    V = _initial_state_basis(t[sel] - t[i0], initial_state_degree)
    coef, *_ = np.linalg.lstsq(V, (qp - qu)[sel], rcond=None)
    e0 = coef[0]
    ed0 = coef[1] if initial_state_degree >= 1 else np.zeros(4)
    n_sel, n_coef = V.shape
    state_cov = np.zeros((8, 8))
    if n_sel > n_coef:
        resid = (qp - qu)[sel] - V @ coef
        var = np.sum(resid**2, axis=0) / (n_sel - n_coef)  # per coordinate
        C = np.linalg.pinv(V.T @ V)
        k = min(n_coef, 2)
        for a in range(4):
            idx = [a, 4 + a][:k]
            state_cov[np.ix_(idx, idx)] = var[a] * C[:k, :k]
    measured = joint_angles(qp[i0 : i1 + 1], pp[i0 : i1 + 1]) - joint_angles(qu[i0 : i1 + 1], pu[i0 : i1 + 1])
    return PreparedWindow(
        params=params,
        time_s=t[i0 : i1 + 1].copy(),
        measured=measured,
        ref_q=np.ascontiguousarray(ref_q),
        ref_qd=np.ascontiguousarray(ref_qd),
        ref_qdd=np.ascontiguousarray(ref_qdd),
        w=np.ascontiguousarray(w),
        force_p=np.ascontiguousarray(force_p),
        dpelvis=np.ascontiguousarray(dpel),
        e0=np.ascontiguousarray(e0),
        ed0=np.ascontiguousarray(ed0),
        dt_s=h,
        n_substeps=n_substeps,
        initial_state_cov=state_cov,
        onset_s=float(onset_s),
        initial_state_span_s=float(initial_state_span_s),
        initial_state_degree=int(initial_state_degree),
    )


def _initial_state_basis(tau: np.ndarray, degree: int) -> np.ndarray:
    """Polynomial basis (n, degree + 1) in the time ``tau`` (s) from window start."""
    return np.vander(tau, int(degree) + 1, increasing=True)


def null_pair_errors(window: PreparedWindow, impedance, null_pairs: dict) -> np.ndarray:
    """Prediction errors (M, m) of pairs without perturbation, at ``impedance``.

    A null pair (:func:`loper_analysis.responses.null_pair_windows`) is an
    unperturbed stride matched to another one: its difference is what a
    perturbed-minus-matched difference holds besides the response. Its
    prediction error is ``eps - G s0``: its measured joint-angle difference
    over the window (rad; samples, then hip/knee/ankle, like the fit's
    residuals) minus the model's free response from its own initial state
    ``s0`` (the pre-onset polynomial, as :func:`prepare_window` takes it; ``G``
    the sensitivity to the initial state, linear about ``impedance``).

    ``null_pairs``: ``time_s`` (n,) relative to the onset on the grid of the
    window's data; ``q_perturbed``, ``q_unperturbed`` (M, n, 4);
    ``pelvis_angle_perturbed_rad``, ``pelvis_angle_unperturbed_rad`` (M, n).
    """
    t = np.asarray(null_pairs["time_s"], dtype=float) + window.onset_s
    qp, qu = (np.asarray(null_pairs[k], dtype=float) for k in ("q_perturbed", "q_unperturbed"))
    pp, pu = (np.asarray(null_pairs[k], dtype=float) for k in ("pelvis_angle_perturbed_rad",
                                                               "pelvis_angle_unperturbed_rad"))
    n_pairs = qp.shape[0]
    if qp.ndim != 3 or qp.shape != qu.shape or qp.shape[1:] != (t.size, 4) or pp.shape != qp.shape[:2] \
            or pu.shape != pp.shape:
        raise LoperInputError(f"null pairs: q arrays must be (M, {t.size}, 4) and pelvis angles (M, {t.size}); got "
                              f"{qp.shape}, {qu.shape}, {pp.shape}, {pu.shape}")
    m = 3 * window.n_samples
    if n_pairs < 1:
        raise LoperInputError("null pairs: none given")
    tol = 1e-6 * window.dt_s * window.n_substeps
    idx = np.searchsorted(t, window.time_s - tol)
    if np.any(idx >= t.size) or np.any(np.abs(t[np.minimum(idx, t.size - 1)] - window.time_s) > tol):
        raise LoperInputError(f"null pairs: their grid ({t[0]:.4f} .. {t[-1]:.4f} s) does not hold the window's "
                              f"samples ({window.time_s[0]:.4f} .. {window.time_s[-1]:.4f} s)")
    sel = (t >= window.onset_s - window.initial_state_span_s - tol) & (t <= window.onset_s + tol)
    V = _initial_state_basis(t[sel] - window.time_s[0], window.initial_state_degree)
    dq = qp - qu
    coef, *_ = np.linalg.lstsq(V, np.moveaxis(dq[:, sel], 1, 0).reshape(sel.sum(), -1), rcond=None)
    coef = coef.reshape(V.shape[1], n_pairs, 4)
    s0 = np.concatenate([coef[0], coef[1] if window.initial_state_degree >= 1 else np.zeros((n_pairs, 4))], axis=1)
    eps = np.stack([joint_angles(qp[i, idx], pp[i, idx]) - joint_angles(qu[i, idx], pu[i, idx])
                    for i in range(n_pairs)]).reshape(n_pairs, m)
    return eps - s0 @ _initial_state_jacobian(window, np.asarray(impedance, dtype=float)).T


def nuisance_projection(errors, n_components: int) -> np.ndarray:
    """Projection (m, m) that removes the ``n_components`` dominant shapes of ``errors``.

    ``errors`` (M, m): e.g. :func:`null_pair_errors`. The shapes are the
    leading right singular vectors ``V`` of the centred errors; the
    projection is ``I - V V^T``. Used as ``PreparedWindow.residual_weight``
    it fits K and D to what these shapes cannot explain, as if their
    amplitudes were free nuisance parameters.
    """
    E = np.asarray(errors, dtype=float)
    if E.ndim != 2 or not np.all(np.isfinite(E)):
        raise LoperInputError(f"errors must be a finite (M, m) array, got shape {E.shape}")
    r = int(n_components)
    if r != n_components or not 0 <= r < min(E.shape):
        raise LoperInputError(f"n_components must be an integer in 0 .. {min(E.shape) - 1} "
                              f"(M = {E.shape[0]} null pairs, m = {E.shape[1]}), got {n_components}")
    _, _, vt = np.linalg.svd(E - E.mean(axis=0), full_matrices=False)
    return np.eye(E.shape[1]) - vt[:r].T @ vt[:r]


# ---------------------------------------------------------------- model response


def _delta_theta(E: np.ndarray, dpel: np.ndarray) -> np.ndarray:
    """Joint-angle deviations (..., n_out, 3) from coordinate deviations (..., n_out, 4)."""
    return np.stack([dpel - E[..., 1], E[..., 2] - E[..., 1], E[..., 2] - E[..., 3]], axis=-1)


def simulate_response(window: PreparedWindow, impedance) -> np.ndarray:
    """Model joint-angle differences perturbed - unperturbed (n_out, 3) or (B, n_out, 3) in rad.

    ``impedance``: (6,) or (B, 6) in the order of :data:`PARAMETERS`.
    """
    P = np.asarray(impedance, dtype=float)
    single = P.ndim == 1
    P2 = np.ascontiguousarray(np.atleast_2d(P))
    if P2.shape[1] != 6 or not np.all(np.isfinite(P2)):
        raise LoperInputError(f"impedance must be finite with 6 values per row, got shape {P.shape}")
    E, _ = _kernels.simulate_deviation_batch(
        P2,
        window.params.packed,
        window.ref_q,
        window.ref_qd,
        window.ref_qdd,
        window.w,
        window.force_p,
        window.dpelvis,
        window.e0,
        window.ed0,
        window.dt_s,
        window.n_substeps,
        window.n_samples,
    )
    dth = _delta_theta(E, window.dpelvis[:: 2 * window.n_substeps, 0])
    return dth[0] if single else dth


def prediction_error(window: PreparedWindow, impedance) -> np.ndarray:
    """PE = measured - model (n_out, 3) or (B, n_out, 3), rad."""
    return window.measured - simulate_response(window, impedance)


def response_jacobian(window: PreparedWindow, impedance, lower=DEFAULT_LOWER, upper=DEFAULT_UPPER) -> np.ndarray:
    """Sensitivity of the model response to the parameters, (n_out * 3, 6).

    Row order: samples, then hip/knee/ankle; units rad per (N m/rad) or per
    (N m s/rad). Forward differences as used by the fit (backward at an upper
    bound). With white noise of SD s on the prediction error,
    ``s * sqrt(diag((J^T J)^-1))`` is the Cramér-Rao bound of the parameter SD.
    """
    lb, ub = _check_bounds(lower, upper)
    p = np.asarray(impedance, dtype=float)
    if p.shape != (6,) or not np.all(np.isfinite(p)):
        raise LoperInputError(f"impedance must be 6 finite values, got {p}")
    _, J = _Evaluator(window, lb, ub).residuals_and_jacobians(p[None])
    return -J[0]


def variance_accounted_for(measured: np.ndarray, model: np.ndarray) -> np.ndarray:
    """VAF per column in %: ``100 (1 - sum (y - y_hat)^2 / sum y^2)``."""
    num = np.sum((measured - model) ** 2, axis=0)
    den = np.sum(measured**2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, 100.0 * (1.0 - num / den), np.nan)


# ---------------------------------------------------------------- optimisation


def _check_bounds(lower, upper) -> tuple[np.ndarray, np.ndarray]:
    lb = np.asarray(lower, dtype=float)
    ub = np.asarray(upper, dtype=float)
    for name, b in (("lower", lb), ("upper", ub)):
        if b.shape != (6,) or not np.all(np.isfinite(b)):
            raise LoperInputError(f"{name} bounds must be 6 finite values ({', '.join(PARAMETERS)}), got {b}")
    bad = np.flatnonzero(lb >= ub)
    if bad.size:
        i = bad[0]
        raise LoperInputError(f"bounds of {PARAMETERS[i]}: lower {lb[i]} must be below upper {ub[i]}")
    return lb, ub


class _Evaluator:
    """Residuals and forward-difference Jacobians for many parameter sets in one batch."""

    def __init__(self, window: PreparedWindow, lb: np.ndarray, ub: np.ndarray):
        self.window = window
        self.lb, self.ub = lb, ub
        self.typical = 0.01 * (ub - lb)
        self.n_sim = 0
        m = 3 * window.n_samples
        for name in ("residual_weight", "noise_cov"):
            value = getattr(window, name)
            if value is not None and (np.shape(value) != (m, m) or not np.all(np.isfinite(value))):
                raise LoperInputError(f"{name} must be a finite ({m}, {m}) matrix, got shape {np.shape(value)}")
        self.weight = None if window.residual_weight is None else np.asarray(window.residual_weight, dtype=float)

    def residuals(self, P: np.ndarray) -> np.ndarray:
        """Prediction errors (B, m), times ``residual_weight`` when the window has one."""
        self.n_sim += len(P)
        r = (self.window.measured - simulate_response(self.window, P)).reshape(len(P), -1)
        return r if self.weight is None else r @ self.weight.T

    def residuals_and_jacobians(self, P: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """r (B, m) and J (B, m, 6) of the residuals at the rows of P."""
        B = len(P)
        step = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(P), self.typical)
        step = np.where(P + step > self.ub, -step, step)
        batch = np.repeat(P[:, None, :], 7, axis=1)
        idx = np.arange(6)
        batch[:, idx + 1, idx] += step
        R = self.residuals(batch.reshape(-1, 6)).reshape(B, 7, -1)
        J = (R[:, 1:, :] - R[:, :1, :]) / step[:, :, None]
        return R[:, 0, :], np.transpose(J, (0, 2, 1))


def _initial_state_jacobian(window: PreparedWindow, impedance: np.ndarray) -> np.ndarray:
    """Sensitivity (m, 8) of the model response (rad) to the initial state [e0, ed0]."""
    base = simulate_response(window, impedance).ravel()
    G = np.empty((base.size, 8))
    for k in range(8):
        h = 1e-6
        e0, ed0 = window.e0.copy(), window.ed0.copy()
        (e0 if k < 4 else ed0)[k % 4] += h
        shifted = replace(window, e0=e0, ed0=ed0)
        G[:, k] = (simulate_response(shifted, impedance).ravel() - base) / h
    return G


def _lm_multistart(ev: _Evaluator, starts: np.ndarray, max_iter: int, tol: float, merge_tol: float):
    """Bound-constrained Levenberg-Marquardt run on all starts at once.

    Residuals and forward-difference Jacobians of every active start are one
    batch of the compiled simulation. Starts that meet (closer than
    ``merge_tol`` of the bound range in every parameter) continue as one.

    Returns final parameters (N, 6), costs (N,) and per-start convergence flags.
    """
    lb, ub = ev.lb, ev.ub
    N = len(starts)
    P = starts.copy()
    r, J = ev.residuals_and_jacobians(P)
    cost = 0.5 * np.sum(r**2, axis=1)
    mu = np.full(N, _MU0)
    active = np.ones(N, bool)
    converged = np.zeros(N, bool)
    merged_into = np.arange(N)
    scale = ub - lb
    for _ in range(max_iter):
        ids = np.flatnonzero(active)
        # a start that has come within merge_tol (fraction of the bounds) of a better
        # active start follows the same path from here: stop it and let it share the result
        if merge_tol > 0 and ids.size > 1:
            order = ids[np.argsort(cost[ids], kind="stable")]
            X = P[order] / scale
            near = np.max(np.abs(X[:, None, :] - X[None, :, :]), axis=2) < merge_tol
            if np.triu(near, 1).any():
                kept: list[int] = []
                for a, i in enumerate(order):
                    partner = next((b for b in kept if near[a, b]), None)
                    if partner is None:
                        kept.append(a)
                    else:
                        merged_into[i] = order[partner]
                        active[i] = False
                ids = np.flatnonzero(active)
        if ids.size == 0:
            break
        trial = np.empty((ids.size, 6))
        for k, i in enumerate(ids):
            g = J[i].T @ r[i]
            A = J[i].T @ J[i]
            at_bound = ((P[i] <= lb) & (g > 0)) | ((P[i] >= ub) & (g < 0))
            free = ~at_bound
            step = np.zeros(6)
            if free.any():
                Af = A[np.ix_(free, free)]
                d = np.diag(Af).copy()
                d[d <= 0] = 1e-12
                try:
                    step[free] = np.linalg.solve(Af + mu[i] * np.diag(d), -g[free])
                except np.linalg.LinAlgError:
                    step[free] = -g[free] / d
            trial[k] = np.clip(P[i] + step, lb, ub)
        rt, Jt = ev.residuals_and_jacobians(trial)
        ct = 0.5 * np.sum(rt**2, axis=1)
        for k, i in enumerate(ids):
            dx = np.abs(trial[k] - P[i])
            small_step = np.all(dx <= tol * (np.abs(P[i]) + ev.typical))
            if ct[k] <= cost[i]:
                gain = cost[i] - ct[k]
                P[i], r[i], J[i] = trial[k], rt[k], Jt[k]
                small_gain = gain <= tol * cost[i] or ct[k] < 1e-30
                cost[i] = ct[k]
                mu[i] = max(mu[i] / _MU_DOWN, 1e-12)
                if small_gain or small_step:
                    active[i] = False
                    converged[i] = True
            else:
                mu[i] *= _MU_UP
                if small_step or mu[i] > 1e12:
                    active[i] = False
                    converged[i] = True
    for i in range(N):  # merged starts share the result of the start they joined
        j = i
        while merged_into[j] != j:
            j = merged_into[j]
        P[i], cost[i], converged[i] = P[j], cost[j], converged[j]
    return P, cost, converged


def identify_impedance(
    window: PreparedWindow,
    *,
    n_starts: int = 10,
    seed: int | np.random.SeedSequence | None = 0,
    lower=DEFAULT_LOWER,
    upper=DEFAULT_UPPER,
    max_iterations: int = 60,
    tolerance: float = 1e-6,
    merge_tolerance: float = 1e-2,
    extra_starts=None,
) -> ImpedanceFit:
    """Fit K, D per joint to one prepared window (see the module docstring).

    Parameters
    ----------
    window : from :func:`prepare_window`.
    n_starts : random starts, drawn uniformly inside the bounds.
    seed : seed of the start generator (NumPy ``default_rng``).
    lower, upper : (6,) bounds in the order of :data:`PARAMETERS`.
    max_iterations : Levenberg-Marquardt iterations per start.
    tolerance : relative cost/step tolerance of the multistart phase; the
        SciPy polish of the best start then converges to machine precision.
    merge_tolerance : starts closer than this fraction of the bound range in
        every parameter continue as one (0 disables merging); a merged start
        counts as reaching the optimum its partner reaches.
    extra_starts : (k, 6) starts tried before the random ones (e.g. a
        previous estimate), clipped to the bounds.

    Returns
    -------
    ImpedanceFit
        ``success`` False (with ``message``) when the optimiser did not
        converge; the estimate is then still the best point found.
    """
    lb, ub = _check_bounds(lower, upper)
    if int(n_starts) != n_starts or n_starts < 1:
        raise LoperInputError(f"n_starts must be an integer >= 1, got {n_starts}")
    rng = np.random.default_rng(seed)
    starts = rng.uniform(lb, ub, size=(int(n_starts), 6))
    if extra_starts is not None:
        extra = np.atleast_2d(np.asarray(extra_starts, dtype=float))
        if extra.shape[1:] != (6,) or not np.all(np.isfinite(extra)):
            raise LoperInputError(f"extra_starts must be finite with 6 values per row, got shape {extra.shape}")
        starts = np.vstack([np.clip(extra, lb, ub), starts])
    ev = _Evaluator(window, lb, ub)
    if not 0 <= merge_tolerance < 1:
        raise LoperInputError(f"merge_tolerance must lie in [0, 1), got {merge_tolerance}")
    P, costs, converged = _lm_multistart(ev, starts, max_iterations, tolerance, merge_tolerance)
    best = int(np.argmin(costs))

    def fun(p):
        return ev.residuals(p[None])[0]

    def jac(p):
        return ev.residuals_and_jacobians(p[None])[1][0]

    polish = least_squares(
        fun, P[best], jac=jac, bounds=(lb, ub), method="trf", x_scale=ev.typical * 100,
        ftol=1e-14, xtol=1e-14, gtol=1e-14, max_nfev=200,
    )
    estimate = np.clip(polish.x, lb, ub)
    cost_polish = 0.5 * float(np.sum(polish.fun**2))
    if cost_polish > costs[best]:  # keep the better of the two (trf steps inside bounds)
        estimate = P[best]
    r, J = ev.residuals_and_jacobians(estimate[None])
    r, J = r[0], J[0]
    pe = prediction_error(window, estimate)
    cost = float(np.sum(pe**2))
    success = bool(polish.status > 0 and converged[best])
    message = polish.message if success else (
        f"not converged: multistart LM converged={bool(converged[best])}, polish status {polish.status} ({polish.message})"
    )
    # how many starts reached the best optimum (same cost within tolerance)
    fit_cost = float(np.sum(r**2))  # the cost minimised (weighted by residual_weight)
    at_best = (np.sum(0.5 * costs <= 0.5 * fit_cost * (1 + 1e-3) + 1e-14) if fit_cost > 0
               else np.sum(costs <= 1e-14))
    n_at_best = int(max(at_best, 1))
    # confidence intervals and correlations from the Jacobian. Without
    # noise_cov: white residual noise plus the uncertainty of the initial
    # state, propagated (sandwich). With noise_cov: the sandwich of the
    # linearised estimator M = (W J)^+ W; noise_cov holds the initial
    # state's share already.
    m = r.size
    dof = max(m - 6, 1)
    s2 = float(np.sum(r**2)) / dof
    JTJ = J.T @ J
    A = np.linalg.pinv(JTJ, rcond=1e-13)
    with np.errstate(divide="ignore", invalid="ignore"):
        if window.noise_cov is None:
            JG = J.T @ _initial_state_jacobian(window, estimate)
            cov = s2 * A + A @ JG @ window.initial_state_cov @ JG.T @ A
        else:
            M = A @ J.T if ev.weight is None else A @ J.T @ ev.weight
            cov = M @ np.asarray(window.noise_cov, dtype=float) @ M.T
        sd = np.sqrt(np.clip(np.diag(cov), 0, None))
        corr = cov / np.outer(sd, sd)
    rank = np.linalg.matrix_rank(JTJ, tol=1e-13 * np.max(np.abs(JTJ)) if np.any(JTJ) else None)
    if rank < 6:
        sd = np.where(np.diag(JTJ) > 0, sd, np.inf)
    half = student_t.ppf(0.975, dof) * sd
    model = window.measured - pe
    vaf = variance_accounted_for(window.measured, model)
    return ImpedanceFit(
        estimate=estimate,
        cost=cost,
        ci95_low=estimate - half,
        ci95_high=estimate + half,
        correlation=corr,
        vaf_pct=vaf,
        success=success,
        message=str(message),
        n_starts=int(n_starts),
        n_starts_at_best=n_at_best,
        n_simulations=ev.n_sim,
        starts=starts,
        start_estimates=P,
        start_costs=2 * costs,
        time_s=window.time_s,
        measured=window.measured,
        model=model,
    )
