"""The identification window: one perturbed/unperturbed pair prepared for the compiled simulation, and its model response.

:func:`prepare_window` checks the inputs of one fit and precomputes the
reference (a cubic spline of the unperturbed coordinates), the feedforward
(its inverse dynamics with the unperturbed force), the perturbed force and
the initial deviation; :func:`simulate_response` integrates the deviation
``e = q_model - q_u`` with fixed-step RK4 for any number of impedance sets
at once; :func:`prediction_error` is measured minus model. Method:
``docs/identification.md``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from .. import kernels
from ..checks import finite_rows
from ..dynamics import SegmentParameters, inverse_dynamics, joint_angles
from ..errors import LoperInputError

__all__ = [
    "PreparedWindow",
    "prepare_window",
    "initial_state_basis",
    "simulate_deviation",
    "joint_angle_deviation",
    "simulate_response",
    "prediction_error",
]


@dataclass(frozen=True)
class PreparedWindow:
    """Everything the compiled simulation needs for one perturbed/unperturbed pair.

    Stage arrays are sampled every ``step_s / 2`` from the window start
    (``2 * n_steps + 1`` rows): the reference coordinates ``reference_q``
    and their first and second derivatives (n_stage, 4; m and rad),
    ``feedforward`` = u_ff - Ja(q_u)^T F_u, the inverse dynamics of the
    reference with the unperturbed force (n_stage, 4; N and N·m),
    ``force_perturbed_n`` (n_stage, 2; N, world x/y) and
    ``pelvis_deviation`` (n_stage, 2): the perturbed-minus-unperturbed pelvis
    angle (rad) and its rate (rad/s). ``measured`` (n_out, 3) is the
    measured perturbed-minus-unperturbed joint angle difference (rad) at the
    window's samples ``time_s`` (n_out,). ``initial_deviation`` and
    ``initial_rate`` (4,) are the coordinate deviation and its rate at window
    start; ``initial_state_cov`` (8, 8) their covariance from the scatter of
    the pre-onset differences about their polynomial (zero for noise-free
    data). ``step_s`` is the RK4 step (s), ``n_substeps`` steps per sample.

    Optional, m = 3 n_out values (samples, then hip/knee/ankle):
    ``residual_weight`` (m, m) multiplies the prediction error before it is
    squared (:func:`loper_analysis.identification.nuisance_projection`);
    ``noise_cov`` (m, m) is the covariance of the prediction error at the true
    impedance (rad^2, e.g. from :func:`loper_analysis.identification.null_pair_errors`
    divided by the number of averaged pairs), from which the CI are taken when given.
    """

    params: SegmentParameters
    time_s: np.ndarray
    measured: np.ndarray
    reference_q: np.ndarray
    reference_qd: np.ndarray
    reference_qdd: np.ndarray
    feedforward: np.ndarray
    force_perturbed_n: np.ndarray
    pelvis_deviation: np.ndarray
    initial_deviation: np.ndarray
    initial_rate: np.ndarray
    step_s: float
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


def _column(name: str, value, n: int, width: int) -> np.ndarray:
    if value is None:
        return np.zeros((n, width))
    a = np.asarray(value, dtype=float)
    if width == 1 and a.ndim == 1:
        a = a[:, None]
    a2, _ = finite_rows(name, a, width)
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
    step = dt / n_substeps
    n_steps = (i1 - i0) * n_substeps
    ts = t[i0] + 0.5 * step * np.arange(2 * n_steps + 1)
    q_ref = qu if q_reference is None else _column("q_reference", q_reference, n, 4)
    if reference_cutoff_hz is not None:
        nyq = 0.5 / dt
        if not 0 < reference_cutoff_hz < nyq:
            raise LoperInputError(f"reference_cutoff_hz must lie in 0 .. {nyq} Hz, got {reference_cutoff_hz}")
        from scipy.signal import (  # only here: scipy.signal costs ~1 s to import
            butter,
            filtfilt,
        )

        b, a = butter(2, reference_cutoff_hz / nyq)
        q_ref = filtfilt(b, a, q_ref, axis=0)
    spline = CubicSpline(t, q_ref, axis=0)
    ref_q = spline(ts)
    ref_qd = spline(ts, 1)
    ref_qdd = spline(ts, 2)
    force_u = np.stack([np.interp(ts, t, fu[:, j]) for j in range(2)], axis=-1)
    force_p = np.stack([np.interp(ts, t, fpm[:, j]) for j in range(2)], axis=-1)
    # u_ff - Ja(q_u)^T F_u = inverse dynamics with the unperturbed force
    feedforward = inverse_dynamics(ref_q, ref_qd, ref_qdd, params, force_u)
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
    V = initial_state_basis(t[sel] - t[i0], initial_state_degree)
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
        reference_q=np.ascontiguousarray(ref_q),
        reference_qd=np.ascontiguousarray(ref_qd),
        reference_qdd=np.ascontiguousarray(ref_qdd),
        feedforward=np.ascontiguousarray(feedforward),
        force_perturbed_n=np.ascontiguousarray(force_p),
        pelvis_deviation=np.ascontiguousarray(dpel),
        initial_deviation=np.ascontiguousarray(e0),
        initial_rate=np.ascontiguousarray(ed0),
        step_s=step,
        n_substeps=n_substeps,
        initial_state_cov=state_cov,
        onset_s=float(onset_s),
        initial_state_span_s=float(initial_state_span_s),
        initial_state_degree=int(initial_state_degree),
    )


def initial_state_basis(tau: np.ndarray, degree: int) -> np.ndarray:
    """Polynomial basis (n, degree + 1) in the time ``tau`` (s) from window start."""
    return np.vander(tau, int(degree) + 1, increasing=True)


def simulate_deviation(window: PreparedWindow, impedance_sets) -> np.ndarray:
    """Model coordinate deviations perturbed - unperturbed (B, n_out, 4) at the window's samples (m, rad).

    ``impedance_sets``: (B, 6) in the order of :data:`~loper_analysis.constants.PARAMETERS`;
    one batch of the compiled RK4 (:func:`loper_analysis.kernels.simulate_deviation_batch`).
    """
    sets = np.ascontiguousarray(np.asarray(impedance_sets, dtype=float))
    if sets.ndim != 2 or sets.shape[1] != 6 or not np.all(np.isfinite(sets)):
        raise LoperInputError(f"impedance must be finite with 6 values per row, got shape {sets.shape}")
    deviation, _ = kernels.simulate_deviation_batch(
        sets,
        window.params.packed,
        window.reference_q,
        window.reference_qd,
        window.reference_qdd,
        window.feedforward,
        window.force_perturbed_n,
        window.pelvis_deviation,
        window.initial_deviation,
        window.initial_rate,
        window.step_s,
        window.n_substeps,
        window.n_samples,
    )
    return deviation


def joint_angle_deviation(deviation: np.ndarray, pelvis_angle_deviation_rad: np.ndarray) -> np.ndarray:
    """Joint-angle deviations (..., n_out, 3) in rad from coordinate deviations (..., n_out, 4) and the pelvis angle's."""
    e, dpel = deviation, pelvis_angle_deviation_rad
    return np.stack([dpel - e[..., 1], e[..., 2] - e[..., 1], e[..., 2] - e[..., 3]], axis=-1)


def simulate_response(window: PreparedWindow, impedance) -> np.ndarray:
    """Model joint-angle differences perturbed - unperturbed (n_out, 3) or (B, n_out, 3) in rad.

    ``impedance``: (6,) or (B, 6) in the order of :data:`PARAMETERS`.
    """
    impedance = np.asarray(impedance, dtype=float)
    if impedance.ndim not in (1, 2) or impedance.shape[-1] != 6 or not np.all(np.isfinite(impedance)):
        raise LoperInputError(f"impedance must be finite with 6 values per row, got shape {impedance.shape}")
    deviation = simulate_deviation(window, np.atleast_2d(impedance))
    dth = joint_angle_deviation(deviation, window.pelvis_deviation[:: 2 * window.n_substeps, 0])
    return dth[0] if impedance.ndim == 1 else dth


def prediction_error(window: PreparedWindow, impedance) -> np.ndarray:
    """PE = measured - model (n_out, 3) or (B, n_out, 3), rad."""
    return window.measured - simulate_response(window, impedance)
