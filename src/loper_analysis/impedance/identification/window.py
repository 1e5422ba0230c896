"""The identification window: one perturbed/unperturbed pair prepared for the compiled simulation, and its model
response.

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

from loper_analysis.checks import finite_rows
from loper_analysis.constants import COUPLINGS, PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.parameters import check_couplings, parameter_names
from loper_analysis.impedance.identification.stage_forces import per_step, stage_force_means, step_stage_forces
from loper_analysis.impedance.responses.response_window import (
    INITIAL_STATE_SPAN_S,
    WINDOW_AFTER_S,
    WINDOW_BEFORE_S,
    ResponseWindow,
)
from loper_analysis.swing_leg import kernels
from loper_analysis.swing_leg.dynamics import SegmentParameters, inverse_dynamics, joint_angles

__all__ = [
    "WINDOW_FIELDS",
    "window_options",
    "WINDOW_BEFORE_S",
    "WINDOW_AFTER_S",
    "INITIAL_STATE_SPAN_S",
    "INITIAL_STATE_DEGREE",
    "N_SUBSTEPS",
    "PreparedWindow",
    "check_couplings",
    "prepare_window",
    "initial_state_basis",
    "stage_force_means",
    "stage_times_s",
    "per_step",
    "step_stage_forces",
    "simulate_deviation",
    "joint_angle_deviation",
    "simulate_response",
    "prediction_error",
]

# Defaults of the fit's initial state and integration (config ``impedance.*``, the same values); the
# window's span (WINDOW_BEFORE_S, WINDOW_AFTER_S, INITIAL_STATE_SPAN_S) is the responses' own
# (:class:`loper_analysis.impedance.responses.response_window.ResponseWindow`): the fit covers the window the responses
# were cut to.
#: Degree of that polynomial (1: position and rate; ``impedance.initial_state_degree``).
INITIAL_STATE_DEGREE: int = 1
#: RK4 steps per sample of the data (``impedance.n_substeps``).
N_SUBSTEPS: int = 2


@dataclass(frozen=True)
class PreparedWindow:
    """Everything the compiled simulation needs for one perturbed/unperturbed pair.

    Stage arrays are sampled every ``step_s / 2`` from the window start
    (``2 * n_steps + 1`` rows): the reference coordinates ``reference_q``
    and their first and second derivatives (n_stage, 4; m and rad),
    ``feedforward`` = u_ff - Ja(q_u)^T F_u, the inverse dynamics of the
    reference with the unperturbed force (n_stage, 4; N and N·m),
    ``force_perturbed_n`` (n_steps, 4, 2; N, world x/y: the thigh rod's force at the four
    stages of every RK4 step), ``shank_force_perturbed_n`` (the same of a second rod at the shank, or None
    without one) and
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
    squared (:func:`loper_analysis.impedance.identification.nuisance_projection`);
    ``noise_cov`` (m, m) is the covariance of the prediction error at the true
    impedance (rad^2, e.g. from :func:`loper_analysis.impedance.identification.null_pair_errors`
    divided by the number of averaged pairs), from which the CI are taken when given.

    ``couplings``: the inter-joint stiffnesses the model adds to K and D (names of
    :data:`~loper_analysis.constants.COUPLINGS`, kept in that order; empty: none). A parameter vector of the window
    holds :attr:`parameters`: the six of :data:`~loper_analysis.constants.PARAMETERS`, then ``K_<coupling>``
    (N·m/rad) for each coupling (:func:`~loper_analysis.swing_leg.kernels.feedback_torques`).
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
    initial_state_span_s: float = INITIAL_STATE_SPAN_S
    initial_state_degree: int = INITIAL_STATE_DEGREE
    noise_cov: np.ndarray | None = None
    residual_weight: np.ndarray | None = None
    shank_force_perturbed_n: np.ndarray | None = None
    couplings: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "couplings", check_couplings(self.couplings))

    @property
    def n_samples(self) -> int:
        return len(self.time_s)

    @property
    def parameters(self) -> tuple[str, ...]:
        """Names of a parameter vector's entries: :data:`PARAMETERS`, then ``K_<coupling>`` per coupling."""
        return parameter_names(self.couplings)

    @property
    def n_parameters(self) -> int:
        """Length of a parameter vector of this window: 6 plus one per coupling."""
        return len(PARAMETERS) + len(self.couplings)


def _column(name: str, value, n: int, width: int, like: str = "time_s") -> np.ndarray:
    if value is None:
        return np.zeros((n, width))
    a = np.asarray(value, dtype=float)
    if width == 1 and a.ndim == 1:
        a = a[:, None]
    a2, _ = finite_rows(name, a, width)
    if a2.shape[0] != n:
        raise LoperInputError(f"{name} has {a2.shape[0]} samples, expected {n} like {like}")
    return a2


#: Fields of a settings object (:class:`~loper_analysis.impedance.identification.validation.ValidationSettings`,
#: :class:`~loper_analysis.planning.window.PlanSettings`) that :func:`prepare_window` takes by name.
WINDOW_FIELDS: tuple[str, ...] = ("window", "n_substeps", "initial_state_degree")


def window_options(settings) -> dict:
    """:func:`prepare_window`'s window keywords (:data:`WINDOW_FIELDS`) from a settings object holding them, and
    its ``couplings`` (inter-joint stiffnesses of the model) when it holds any."""
    options = {name: getattr(settings, name) for name in WINDOW_FIELDS}
    if getattr(settings, "couplings", ()):
        options["couplings"] = settings.couplings
    return options


def prepare_window(
    time_s,
    q_unperturbed,
    q_perturbed,
    params: SegmentParameters,
    onset_s: float,
    *,
    force_unperturbed_n=None,
    force_perturbed_n=None,
    force_time_s=None,
    shank_force_unperturbed_n=None,
    shank_force_perturbed_n=None,
    pelvis_angle_unperturbed_rad=None,
    pelvis_angle_perturbed_rad=None,
    window: ResponseWindow = ResponseWindow(),
    n_substeps: int = N_SUBSTEPS,
    reference_cutoff_hz: float | None = None,
    q_reference=None,
    initial_state_degree: int = INITIAL_STATE_DEGREE,
    couplings=(),
) -> PreparedWindow:
    """Check the inputs of one fit and precompute reference, inputs and initial state.

    Parameters
    ----------
    time_s : (n,) uniformly sampled time (s); the window must lie inside it.
    q_unperturbed, q_perturbed : (n, 4) measured coordinates [x (m), thigh,
        shank, foot (rad)] of the unperturbed and the perturbed stride,
        aligned so that the onset is at ``onset_s`` in both.
    force_unperturbed_n, force_perturbed_n : (n, 2) rod force (N, world x/y)
        at the attachment point; zero when omitted. With ``force_time_s``
        they are (k, 2) instead, sampled at ``force_time_s``.
    force_time_s : (k,) optional sample times (s, the clock of ``time_s``)
        of the forces at their own rate (e.g. the robot log's 1000 Hz). Each
        force is then the cubic spline through its samples; the feedforward
        takes ``F_u`` as its mean over each stage's share of the step
        (:func:`stage_force_means`), and the rod force of the perturbed leg is
        ``F_u`` plus ``F_p - F_u`` as stage forces that give every RK4 step the
        exact impulse and timing of the force (:func:`step_stage_forces`), so
        that a 10 ms edge needs no step shorter than the default. The samples
        must cover the fit window. Without it the forces are (n, 2) at
        ``time_s`` and are interpolated linearly at the stage times.
    shank_force_unperturbed_n, shank_force_perturbed_n : a second rod's force at the shank (N, world x/y), as the
        thigh rod's and on its clock; for ``params`` with a ``shank_attachment_m``; None: no shank rod.
    pelvis_angle_*_rad : (n,) pelvis angle (rad); zero when omitted.
    window : the window around the onset (``before_s``, ``after_s``, s) and the span before it for the initial
        state (``initial_state_span_s``, s;
        :class:`~loper_analysis.impedance.responses.response_window.ResponseWindow`).
    n_substeps : RK4 steps per sample (integer >= 1).
    reference_cutoff_hz : if given, the unperturbed coordinates are low-pass
        filtered (2nd-order zero-phase Butterworth) before they serve as the
        reference whose derivatives give ``u_ff``; the measured differences
        in the prediction error stay unfiltered.
    q_reference : (n, 4) optional smooth reference coordinates for ``u_ff``
        and the feedback operating point (e.g. the mean of many unperturbed
        strides); ``q_unperturbed`` when omitted.
    initial_state_degree : the initial deviation and
        its rate at window start come from a least-squares polynomial of this
        degree through the perturbed-minus-unperturbed coordinates over the
        last ``window.initial_state_span_s`` before the onset, when the perturbation
        has not yet acted (robust to measurement noise; exact for smooth data).
    couplings : inter-joint stiffnesses of the model besides K and D per joint, names of
        :data:`~loper_analysis.constants.COUPLINGS` (e.g. ``("hip_knee",)``); the window's parameter vectors then
        hold ``K_<coupling>`` after the six (:attr:`PreparedWindow.parameters`). Empty: none.

    Raises
    ------
    LoperInputError
        Non-finite or wrongly shaped inputs, non-uniform time, a window
        outside the data, forces at their own rate that do not cover the window.
    """
    t = _finite_times("time_s", time_s, 4)
    dt = _uniform_step_s(t)
    n = len(t)
    qu = _column("q_unperturbed", q_unperturbed, n, 4)
    qp = _column("q_perturbed", q_perturbed, n, 4)
    tf = None
    if force_time_s is None:
        fu = _column("force_unperturbed_n", force_unperturbed_n, n, 2)
        fpm = _column("force_perturbed_n", force_perturbed_n, n, 2)
    else:
        tf = _force_clock(force_time_s)
        fu = _column("force_unperturbed_n", force_unperturbed_n, len(tf), 2, "force_time_s")
        fpm = _column("force_perturbed_n", force_perturbed_n, len(tf), 2, "force_time_s")
    su, sp = _shank_forces(params, shank_force_unperturbed_n, shank_force_perturbed_n, n if tf is None else len(tf))
    pu = _column("pelvis_angle_unperturbed_rad", pelvis_angle_unperturbed_rad, n, 1)[:, 0]
    pp = _column("pelvis_angle_perturbed_rad", pelvis_angle_perturbed_rad, n, 1)[:, 0]
    if not isinstance(window, ResponseWindow):
        raise LoperInputError(f"window must be a ResponseWindow, got {type(window).__name__}")
    initial_state_span_s = window.initial_state_span_s
    i0, i1, n_substeps = _window_samples(t, dt, onset_s, window.before_s, window.after_s, n_substeps)
    tol = 1e-9 * dt

    # reference: cubic spline of the unperturbed coordinates, at RK4 stage times
    step = dt / n_substeps
    n_steps = (i1 - i0) * n_substeps
    ts = t[i0] + 0.5 * step * np.arange(2 * n_steps + 1)
    q_ref = qu if q_reference is None else _column("q_reference", q_reference, n, 4)
    ref_q, ref_qd, ref_qdd = _reference_coordinates(t, dt, q_ref, ts, reference_cutoff_hz)
    force_u, force_p = _stage_forces(t, fu, fpm, tf, ts, step, n_steps)
    shank_u, shank_p = (None, None) if su is None else _stage_forces(t, su, sp, tf, ts, step, n_steps)
    # u_ff - Ja(q_u)^T F_u = inverse dynamics with the unperturbed force (of both rods)
    feedforward = inverse_dynamics(ref_q, ref_qd, ref_qdd, params, force_u, shank_u)
    dpel_spline = CubicSpline(t, pp - pu)
    dpel = np.stack([dpel_spline(ts), dpel_spline(ts, 1)], axis=-1)
    e0, ed0, state_cov = _initial_state(t, qp - qu, i0, onset_s, initial_state_span_s, initial_state_degree, tol)
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
        shank_force_perturbed_n=None if shank_p is None else np.ascontiguousarray(shank_p),
        couplings=couplings,
    )


def _shank_forces(params: SegmentParameters, unperturbed, perturbed, k: int):
    """The shank rod's forces (k, 2) each (zero when one is omitted), or (None, None) without either."""
    if unperturbed is None and perturbed is None:
        return None, None
    if params.shank_attachment_m is None:
        raise LoperInputError(
            "a shank rod's force is given, but the segment parameters place no rod on the shank "
            "(shank_attachment_m None)"
        )
    return (
        _column("shank_force_unperturbed_n", unperturbed, k, 2, "the thigh rod's force"),
        _column("shank_force_perturbed_n", perturbed, k, 2, "the thigh rod's force"),
    )


def _uniform_step_s(t: np.ndarray) -> float:
    """The mean step (s) of the sample times ``t`` (n,), checked to increase uniformly (to 1e-6 of the step)."""
    dts = np.diff(t)
    dt = float(np.mean(dts))
    if dt <= 0 or np.max(np.abs(dts - dt)) > 1e-6 * dt:
        i = int(np.argmax(np.abs(dts - dt)))
        raise LoperInputError(f"time_s must be uniformly increasing; step at sample {i} is {dts[i]} s, mean {dt} s")
    return dt


def _window_samples(
    t: np.ndarray, dt: float, onset_s: float, window_before_s: float, window_after_s: float, n_substeps: int
) -> tuple[int, int, int]:
    """First and last sample (indices into ``t``, step ``dt`` s) of the window ``onset_s - window_before_s ..
    onset_s + window_after_s`` (s), checked to lie inside the data and hold >= 4 samples, and ``n_substeps``
    checked to be an integer >= 1."""
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
    n = len(t)
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
    return i0, i1, n_substeps


def _reference_coordinates(
    t: np.ndarray, dt: float, q_ref: np.ndarray, stage_time_s: np.ndarray, reference_cutoff_hz: float | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The reference coordinates (m, rad) and their first and second derivatives, each (n_stage, 4) at the
    stage times: the cubic spline through ``q_ref`` (n, 4) at ``t`` (n,; step ``dt`` s), low-pass filtered
    first (2nd-order zero-phase Butterworth) when ``reference_cutoff_hz`` is given."""
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
    return spline(stage_time_s), spline(stage_time_s, 1), spline(stage_time_s, 2)


def _stage_forces(
    t: np.ndarray,
    force_u: np.ndarray,
    force_p: np.ndarray,
    force_time_s: np.ndarray | None,
    stage_time_s: np.ndarray,
    step_s: float,
    n_steps: int,
) -> tuple[np.ndarray, np.ndarray]:
    """The unperturbed force at the stage times (n_stage, 2) and the perturbed force at the four stages of every
    RK4 step (n_steps, 4, 2) of ``step_s`` s, N, world x/y.

    ``force_u``, ``force_p``: the forces at ``t`` (n, 2), interpolated linearly; with ``force_time_s`` (k,) the
    forces (k, 2) at their own rate, which must cover the stage times (:func:`stage_force_means`,
    :func:`step_stage_forces`).
    """
    ts = stage_time_s
    if force_time_s is None:
        stage_u = np.stack([np.interp(ts, t, force_u[:, j]) for j in range(2)], axis=-1)
        return stage_u, per_step(np.stack([np.interp(ts, t, force_p[:, j]) for j in range(2)], axis=-1))
    tf, step = force_time_s, step_s
    tol_f = 1e-6 * step
    if tf[0] > ts[0] + tol_f or tf[-1] < ts[-1] - tol_f:
        raise LoperInputError(
            f"the force at its own rate ({tf[0]:.4f} .. {tf[-1]:.4f} s) does not cover the fit window "
            f"{ts[0]:.4f} .. {ts[-1]:.4f} s"
        )
    stage_u = stage_force_means(tf, force_u, ts)
    return stage_u, per_step(stage_u) + step_stage_forces(tf, force_p - force_u, ts[0], step, n_steps)


def _initial_state(
    t: np.ndarray,
    deviation: np.ndarray,
    i0: int,
    onset_s: float,
    initial_state_span_s: float,
    initial_state_degree: int,
    tol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The coordinate deviation (4,) and its rate (4,) at window start (sample ``i0``) and their covariance (8, 8).

    From a least-squares polynomial of ``initial_state_degree`` through the perturbed-minus-unperturbed
    coordinates ``deviation`` (n, 4; m, rad) at ``t`` (n,) over the last ``initial_state_span_s`` (s) up to
    the onset (``tol`` s of slack); the covariance from the scatter about it (zero without spare samples).
    """
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
    coef, *_ = np.linalg.lstsq(V, deviation[sel], rcond=None)
    e0 = coef[0]
    ed0 = coef[1] if initial_state_degree >= 1 else np.zeros(4)
    n_sel, n_coef = V.shape
    state_cov = np.zeros((8, 8))
    if n_sel > n_coef:
        resid = deviation[sel] - V @ coef
        var = np.sum(resid**2, axis=0) / (n_sel - n_coef)  # per coordinate
        C = np.linalg.pinv(V.T @ V)
        k = min(n_coef, 2)
        for a in range(4):
            idx = [a, 4 + a][:k]
            state_cov[np.ix_(idx, idx)] = var[a] * C[:k, :k]
    return e0, ed0, state_cov


def stage_times_s(window: PreparedWindow) -> np.ndarray:
    """The RK4 stage times (2 N + 1,) in s of a window: every ``step_s / 2`` from its first sample."""
    n_steps = (window.n_samples - 1) * window.n_substeps
    return window.time_s[0] + 0.5 * window.step_s * np.arange(2 * n_steps + 1)


def _finite_times(name: str, value, min_samples: int) -> np.ndarray:
    """Sample times (s) as a 1-D float array of at least ``min_samples`` finite values; ``name`` in messages."""
    t = np.asarray(value, dtype=float)
    if t.ndim != 1 or len(t) < min_samples:
        raise LoperInputError(f"{name} must be 1-D with >= {min_samples} samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise LoperInputError(f"{name} is not finite at sample {int(np.argmax(~np.isfinite(t)))}")
    return t


def _force_clock(force_time_s) -> np.ndarray:
    tf = _finite_times("force_time_s", force_time_s, 2)
    d = np.diff(tf)
    if np.any(d <= 0):
        i = int(np.argmax(d <= 0))
        raise LoperInputError(f"force_time_s must be strictly increasing; step at sample {i} is {d[i]} s")
    return tf


def initial_state_basis(tau: np.ndarray, degree: int) -> np.ndarray:
    """Polynomial basis (n, degree + 1) in the time ``tau`` (s) from window start."""
    return np.vander(tau, int(degree) + 1, increasing=True)


def simulate_deviation(window: PreparedWindow, impedance_sets) -> np.ndarray:
    """Model coordinate deviations perturbed - unperturbed (B, n_out, 4) at the window's samples (m, rad).

    ``impedance_sets``: (B, p) in the order of the window's :attr:`~PreparedWindow.parameters` (p = 6 without
    couplings: :data:`~loper_analysis.constants.PARAMETERS`); one batch of the compiled RK4
    (:func:`loper_analysis.swing_leg.kernels.simulate_deviation_batch`, given the six and, with couplings, both
    coupling stiffnesses, 0 for a coupling the window does not hold; without couplings its variant without them).
    """
    sets = np.ascontiguousarray(np.asarray(impedance_sets, dtype=float))
    n = window.n_parameters
    if sets.ndim != 2 or sets.shape[1] != n or not np.all(np.isfinite(sets)):
        raise LoperInputError(
            f"impedance must be finite with {n} values per row ({', '.join(window.parameters)}), got shape {sets.shape}"
        )
    extra = ()
    if window.couplings:
        stiffness = np.zeros((len(sets), len(COUPLINGS)))
        for k, c in enumerate(window.couplings):
            stiffness[:, COUPLINGS.index(c)] = sets[:, len(PARAMETERS) + k]
        sets, extra = np.ascontiguousarray(sets[:, : len(PARAMETERS)]), (stiffness,)
    deviation, _ = kernels.simulate_deviation_batch(
        sets,
        window.params.packed,
        window.reference_q,
        window.reference_qd,
        window.reference_qdd,
        window.feedforward,
        window.force_perturbed_n,
        _shank_force(window),
        window.pelvis_deviation,
        window.initial_deviation,
        window.initial_rate,
        window.step_s,
        window.n_substeps,
        window.n_samples,
        *extra,
    )
    return deviation


def _shank_force(window: PreparedWindow) -> np.ndarray:
    """The shank rod's stage forces (n_steps, 4, 2), zero without a shank rod."""
    if window.shank_force_perturbed_n is None:
        return np.zeros_like(window.force_perturbed_n)
    return window.shank_force_perturbed_n


def joint_angle_deviation(deviation: np.ndarray, pelvis_angle_deviation_rad: np.ndarray) -> np.ndarray:
    """Joint-angle deviations (..., n_out, 3) in rad from coordinate deviations (..., n_out, 4) and the pelvis
    angle's."""
    e, dpel = deviation, pelvis_angle_deviation_rad
    return np.stack([dpel - e[..., 1], e[..., 2] - e[..., 1], e[..., 2] - e[..., 3]], axis=-1)


def simulate_response(window: PreparedWindow, impedance) -> np.ndarray:
    """Model joint-angle differences perturbed - unperturbed (n_out, 3) or (B, n_out, 3) in rad.

    ``impedance``: (p,) or (B, p) in the order of the window's :attr:`~PreparedWindow.parameters` (p = 6 without
    couplings: :data:`PARAMETERS`).
    """
    impedance = np.asarray(impedance, dtype=float)
    n = window.n_parameters
    if impedance.ndim not in (1, 2) or impedance.shape[-1] != n or not np.all(np.isfinite(impedance)):
        raise LoperInputError(
            f"impedance must be finite with {n} values per row ({', '.join(window.parameters)}), "
            f"got shape {impedance.shape}"
        )
    deviation = simulate_deviation(window, np.atleast_2d(impedance))
    dth = joint_angle_deviation(deviation, window.pelvis_deviation[:: 2 * window.n_substeps, 0])
    return dth[0] if impedance.ndim == 1 else dth


def prediction_error(window: PreparedWindow, impedance) -> np.ndarray:
    """PE = measured - model (n_out, 3) or (B, n_out, 3), rad."""
    return window.measured - simulate_response(window, impedance)
