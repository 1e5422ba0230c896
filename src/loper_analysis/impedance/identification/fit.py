"""Fitting K and D per joint to one prepared window: multistart Levenberg-Marquardt, SciPy polish, CIs, VAF.

Cost
----
One definition throughout: the **cost** of an impedance vector is the sum of
squared residuals ``r = W PE`` (rad^2), where ``PE`` is the prediction error
over the window (samples, then hip/knee/ankle) and ``W`` the window's
``residual_weight`` (the identity for a white-noise fit). It is what the
optimiser minimises, what every start ends with (``start_costs``) and what
``n_starts_at_best`` compares. The plain sum of squared prediction errors
(unweighted) is reported beside it as ``sum_sq_error_rad2``.

Optimiser
---------
Random starts drawn uniformly inside the bounds are iterated *together* by
a bound-constrained Levenberg-Marquardt (:func:`multistart_lm`) whose
residuals and forward-difference Jacobians for all active starts come from
one batch of the compiled simulation; starts that come within
``merge_tolerance`` of the bound range of a better start (every parameter)
continue as one and share its result. The best start is polished by
:func:`scipy.optimize.least_squares` (trust-region reflective, bounds),
whose status is the fit's status. Per-start ``least_squares`` was measured
as the alternative and is slower here (``docs/identification.md``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares

from loper_analysis.constants import PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.intervals import bounded_interval, sandwich_covariance
from loper_analysis.impedance.identification.parameters import (
    COUPLING_BOUNDS_NM_PER_RAD,
    DAMPING_BOUNDS_NMS_PER_RAD,
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    STIFFNESS_BOUNDS_NM_PER_RAD,
    FitBounds,
    check_bounds,
    check_couplings,
    fit_bounds,
    parameter_bounds,
)
from loper_analysis.impedance.identification.window import PreparedWindow, prediction_error, simulate_response

__all__ = [
    "DEFAULT_LOWER",
    "DEFAULT_UPPER",
    "STIFFNESS_BOUNDS_NM_PER_RAD",
    "DAMPING_BOUNDS_NMS_PER_RAD",
    "COUPLING_BOUNDS_NM_PER_RAD",
    "N_STARTS",
    "FIT_TOLERANCE",
    "MERGE_TOLERANCE",
    "AT_BEST_RELATIVE",
    "ImpedanceFit",
    "check_bounds",
    "fit_bounds",
    "parameter_bounds",
    "FitBounds",
    "ResidualBatch",
    "initial_state_jacobian",
    "multistart_lm",
    "starts_at_best",
    "identify_impedance",
    "response_jacobian",
    "variance_accounted_for",
]

#: Random starts drawn uniformly inside the bounds (``impedance.n_starts``).
N_STARTS: int = 10
#: Relative cost/step tolerance of the multistart phase (``impedance.tolerance``).
FIT_TOLERANCE: float = 1e-6
#: Starts this close (fraction of the bounds, every parameter) continue as one (``impedance.merge_tolerance``).
MERGE_TOLERANCE: float = 1e-2
#: A start has reached the best when its final cost is within this fraction above the lowest start cost.
AT_BEST_RELATIVE = 1e-3
#: Levenberg-Marquardt damping: initial value, factor down after a successful step, factor up after a failed one.
_MU_START, _MU_DOWN, _MU_UP = 1e-2, 10.0, 10.0
#: A cost below this (rad^2) is zero: the fit is exact to rounding.
_COST_ZERO = 2e-30


@dataclass
class ImpedanceFit:
    """Result of :func:`identify_impedance` (parameter order :attr:`parameters`: :data:`PARAMETERS`, then
    ``K_<coupling>`` for each inter-joint coupling of the fit).

    ``cost`` and ``start_costs`` are costs as defined in the module docstring
    (rad^2); ``sum_sq_error_rad2`` is the unweighted sum of squared prediction
    errors at the estimate; ``sd`` the parameters' standard deviations (linearised; inf: no information) and
    ``ci_dof`` the degrees of freedom of the intervals' t quantile; ``n_starts_at_best`` counts the starts whose final
    cost lies within :data:`AT_BEST_RELATIVE` above the lowest start cost. ``estimate``, ``sd``, ``ci95_low`` and
    ``ci95_high`` are (p,), ``correlation`` (p, p), p = ``len(parameters)``.
    """

    estimate: np.ndarray
    cost: float
    sum_sq_error_rad2: float
    ci95_low: np.ndarray
    ci95_high: np.ndarray
    sd: np.ndarray
    ci_dof: int
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
    parameters: tuple[str, ...] = PARAMETERS

    def value(self, name: str) -> tuple[float, float, float, float]:
        """Estimate, SD, 95 % CI low and high of the parameter ``name`` (one of :attr:`parameters`)."""
        if name not in self.parameters:
            raise LoperInputError(f"the fit holds {', '.join(self.parameters)}; no {name!r}")
        i = self.parameters.index(name)
        return float(self.estimate[i]), float(self.sd[i]), float(self.ci95_low[i]), float(self.ci95_high[i])


def response_jacobian(window: PreparedWindow, impedance, lower=DEFAULT_LOWER, upper=DEFAULT_UPPER) -> np.ndarray:
    """Sensitivity of the model response to the parameters, (n_out * 3, p).

    Row order: samples, then hip/knee/ankle; columns the window's parameters (p = 6 without inter-joint
    couplings; :attr:`PreparedWindow.parameters`); units rad per (N m/rad) or per
    (N m s/rad). Forward differences as used by the fit (backward at an upper
    bound). With white noise of SD s on the prediction error,
    ``s * sqrt(diag((J^T J)^-1))`` is the Cramér-Rao bound of the parameter SD. ``lower``, ``upper``: as
    :func:`identify_impedance` takes them (:func:`fit_bounds`).
    """
    lb, ub = fit_bounds(lower, upper, window.couplings)
    p = np.asarray(impedance, dtype=float)
    if p.shape != (window.n_parameters,) or not np.all(np.isfinite(p)):
        raise LoperInputError(
            f"impedance must be {window.n_parameters} finite values ({', '.join(window.parameters)}), got {p}"
        )
    _, jacobian = ResidualBatch(window, lb, ub).residuals_and_jacobians(p[None])
    return -jacobian[0]


def variance_accounted_for(measured: np.ndarray, model: np.ndarray) -> np.ndarray:
    """VAF per column in %: ``100 (1 - sum (y - y_hat)^2 / sum y^2)``."""
    num = np.sum((measured - model) ** 2, axis=0)
    den = np.sum(measured**2, axis=0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, 100.0 * (1.0 - num / den), np.nan)


class ResidualBatch:
    """Residuals and forward-difference Jacobians for many parameter sets in one batch of simulations."""

    def __init__(self, window: PreparedWindow, lb: np.ndarray, ub: np.ndarray):
        self.window = window
        self.lb, self.ub = lb, ub
        self.typical = 0.01 * (ub - lb)
        self.n_simulations = 0
        m = 3 * window.n_samples
        for name in ("residual_weight", "noise_cov"):
            value = getattr(window, name)
            if value is not None and (np.shape(value) != (m, m) or not np.all(np.isfinite(value))):
                raise LoperInputError(f"{name} must be a finite ({m}, {m}) matrix, got shape {np.shape(value)}")
        self.weight = None if window.residual_weight is None else np.asarray(window.residual_weight, dtype=float)

    def residuals(self, impedance_sets: np.ndarray) -> np.ndarray:
        """Prediction errors (B, m), times ``residual_weight`` when the window has one."""
        self.n_simulations += len(impedance_sets)
        r = (self.window.measured - simulate_response(self.window, impedance_sets)).reshape(len(impedance_sets), -1)
        return r if self.weight is None else r @ self.weight.T

    def cost(self, impedance_sets: np.ndarray) -> np.ndarray:
        """Costs (B,) at the rows of ``impedance_sets``; ``inf`` where the simulation diverged (:func:`costs_of`)."""
        return costs_of(self.residuals(impedance_sets))

    def residuals_and_jacobians(self, impedance_sets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """r (B, m) and J (B, m, p) of the residuals at the rows of ``impedance_sets`` (B, p)."""
        sets = impedance_sets
        B = len(sets)
        n = len(self.lb)
        step = np.sqrt(np.finfo(float).eps) * np.maximum(np.abs(sets), self.typical)
        step = np.where(sets + step > self.ub, -step, step)
        batch = np.repeat(sets[:, None, :], n + 1, axis=1)
        idx = np.arange(n)
        batch[:, idx + 1, idx] += step
        R = self.residuals(batch.reshape(-1, n)).reshape(B, n + 1, -1)
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged simulation: inf - inf
            J = (R[:, 1:, :] - R[:, :1, :]) / step[:, :, None]
        return R[:, 0, :], np.transpose(J, (0, 2, 1))


def initial_state_jacobian(window: PreparedWindow, impedance) -> np.ndarray:
    """Sensitivity (m, 8) of the model response (rad) to the initial deviation and its rate, at ``impedance``."""
    impedance = np.asarray(impedance, dtype=float)
    base = simulate_response(window, impedance).ravel()
    G = np.empty((base.size, 8))
    for k in range(8):
        h = 1e-6
        e0, ed0 = window.initial_deviation.copy(), window.initial_rate.copy()
        (e0 if k < 4 else ed0)[k % 4] += h
        shifted = replace(window, initial_deviation=e0, initial_rate=ed0)
        G[:, k] = (simulate_response(shifted, impedance).ravel() - base) / h
    return G


def costs_of(residuals: np.ndarray) -> np.ndarray:
    """Sums of squares (B,) of residual rows (B, m); ``inf`` for a row that is not finite or whose square
    overflows.

    A start whose simulation diverges (a negative stiffness within signed bounds makes the response grow
    exponentially) is a normal event of a multistart fit: its cost is infinite, so every comparison rejects it,
    with no floating-point warning on any CPU.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        c = np.sum(np.square(residuals), axis=1)
    c[~np.isfinite(c)] = np.inf
    return c


def _merge_close(
    points: np.ndarray,
    cost: np.ndarray,
    active: np.ndarray,
    merged_into: np.ndarray,
    scale: np.ndarray,
    merge_tol: float,
) -> None:
    """Stop each active start within ``merge_tol`` (fraction of ``scale``, every parameter) of a better active one."""
    ids = np.flatnonzero(active)
    if merge_tol <= 0 or ids.size < 2:
        return
    order = ids[np.argsort(cost[ids], kind="stable")]
    scaled = points[order] / scale
    near = np.max(np.abs(scaled[:, None, :] - scaled[None, :, :]), axis=2) < merge_tol
    if not np.triu(near, 1).any():
        return
    kept: list[int] = []
    for a, i in enumerate(order):
        partner = next((b for b in kept if near[a, b]), None)
        if partner is None:
            kept.append(a)
        else:
            merged_into[i] = order[partner]
            active[i] = False


def multistart_lm(batch: ResidualBatch, starts: np.ndarray, max_iter: int, tol: float, merge_tol: float):
    """Bound-constrained Levenberg-Marquardt run on all starts at once.

    Residuals and forward-difference Jacobians of every active start are one
    batch of the compiled simulation. A start that comes within ``merge_tol``
    of the bound range (every parameter) of a better active start follows the
    same path from there: it stops and shares that start's result. A start
    stops when its cost gain or its step falls below ``tol`` (relative).

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, numpy.ndarray, numpy.ndarray)
        Final parameters (N, p), final costs (N,), per-start convergence flags
        (N,) and ``merged_into`` (N,): the start whose result each start shares
        (itself when it was never merged).
    """
    lb, ub = batch.lb, batch.ub
    n_par = len(lb)
    N = len(starts)
    points = starts.copy()
    r, J = batch.residuals_and_jacobians(points)
    cost = costs_of(r)
    mu = np.full(N, _MU_START)
    active = np.isfinite(cost)  # a start whose simulation diverged at once takes no step
    converged = np.zeros(N, bool)
    merged_into = np.arange(N)
    scale = ub - lb
    for _ in range(max_iter):
        _merge_close(points, cost, active, merged_into, scale, merge_tol)
        ids = np.flatnonzero(active)
        if ids.size == 0:
            break
        trial = np.empty((ids.size, n_par))
        for k, i in enumerate(ids):
            with np.errstate(over="ignore", invalid="ignore"):  # huge sensitivities of a nearly diverging start
                g = J[i].T @ r[i]
                A = J[i].T @ J[i]
            if not (np.all(np.isfinite(g)) and np.all(np.isfinite(A))):
                trial[k] = points[i]  # no step: the trial equals the point and is rejected, its damping grows
                continue
            at_bound = ((points[i] <= lb) & (g > 0)) | ((points[i] >= ub) & (g < 0))
            free = ~at_bound
            step = np.zeros(n_par)
            if free.any():
                Af = A[np.ix_(free, free)]
                d = np.diag(Af).copy()
                d[d <= 0] = 1e-12
                try:
                    step[free] = np.linalg.solve(Af + mu[i] * np.diag(d), -g[free])
                except np.linalg.LinAlgError:
                    step[free] = -g[free] / d
            if not np.all(np.isfinite(step)):  # a start whose simulation overflowed: no step, its damping grows
                step = np.zeros(n_par)
            trial[k] = np.clip(points[i] + step, lb, ub)
        rt, Jt = batch.residuals_and_jacobians(trial)
        ct = costs_of(rt)
        for k, i in enumerate(ids):
            dx = np.abs(trial[k] - points[i])
            small_step = np.all(dx <= tol * (np.abs(points[i]) + batch.typical))
            if ct[k] <= cost[i] and np.isfinite(ct[k]) and not np.array_equal(trial[k], points[i]):
                gain = cost[i] - ct[k]
                points[i], r[i], J[i] = trial[k], rt[k], Jt[k]
                small_gain = gain <= tol * cost[i] or ct[k] < _COST_ZERO
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
        merged_into[i] = j
        points[i], cost[i], converged[i] = points[j], cost[j], converged[j]
    return points, cost, converged, merged_into


def starts_at_best(start_costs, relative: float = AT_BEST_RELATIVE) -> int:
    """How many starts ended within ``relative`` above the lowest start cost (at least 1).

    A cost of exactly zero (noise-free data fitted to rounding) counts as reached by every start at zero.
    A cost of +inf (a start whose simulation diverged) never counts; at least one cost must be finite.
    """
    costs = np.asarray(start_costs, dtype=float)
    if (
        costs.ndim != 1
        or costs.size == 0
        or np.any(np.isnan(costs))
        or np.any(costs < 0)
        or not np.any(np.isfinite(costs))
    ):
        raise LoperInputError(f"start costs must be a non-empty array >= 0 (+inf allowed, not all), got {costs}")
    best = costs.min()
    return int(np.sum(costs <= best * (1.0 + relative)))


def identify_impedance(
    window: PreparedWindow,
    *,
    n_starts: int = N_STARTS,
    seed: int | np.random.SeedSequence | None = 0,
    lower=DEFAULT_LOWER,
    upper=DEFAULT_UPPER,
    max_iterations: int = 60,
    tolerance: float = FIT_TOLERANCE,
    merge_tolerance: float = MERGE_TOLERANCE,
    extra_starts=None,
    ci_dof: int | None = None,
    polish_max_evaluations: int = 200,
    couplings=None,
) -> ImpedanceFit:
    """Fit K, D per joint to one prepared window (method: ``docs/identification.md``).

    Parameters
    ----------
    window : from :func:`loper_analysis.impedance.identification.prepare_window`.
    n_starts : random starts, drawn uniformly inside the bounds.
    seed : seed of the start generator (NumPy ``default_rng``).
    lower, upper : (p,) bounds in the order of the fit's parameters (:attr:`ImpedanceFit.parameters`), or the six
        of :data:`PARAMETERS` alone, to which each coupling's :data:`COUPLING_BOUNDS_NM_PER_RAD` is appended
        (:func:`fit_bounds`).
    max_iterations : Levenberg-Marquardt iterations per start.
    tolerance : relative cost/step tolerance of the multistart phase; the
        SciPy polish of the best start then converges to machine precision.
    merge_tolerance : starts closer than this fraction of the bound range in
        every parameter continue as one (0 disables merging); a merged start
        ends with the cost of the start it joined.
    extra_starts : (k, p) starts tried before the random ones (e.g. a
        previous estimate), clipped to the bounds; with couplings also (k, 6), the couplings starting at 0.
    ci_dof : degrees of freedom of the intervals' t quantile; None: the
        residuals' ``m - p`` (white fit). A fit whose ``noise_cov`` comes from
        ``N`` null pairs passes ``N - 1`` (:mod:`.intervals`).
    polish_max_evaluations : most residual evaluations of the SciPy polish.
    couplings : inter-joint stiffnesses fitted besides K and D per joint (names of
        :data:`~loper_analysis.constants.COUPLINGS`, e.g. ``("hip_knee",)``: the bi-articular hip-knee stiffness
        ``K_hip_knee``, N·m/rad); None: the window's own (:attr:`PreparedWindow.couplings`, set by
        :func:`~loper_analysis.impedance.identification.prepare_window`). The estimate, SD, intervals and
        correlation then hold them after the six.

    Returns
    -------
    ImpedanceFit
        ``success`` False (with ``message``) when the polish of the best
        start did not converge (a minimum is what the estimate must be;
        the multistart phase only has to bring it there, so a best start
        that used up ``max_iterations`` and was then polished to a minimum
        counts as converged); the estimate is then still the best point found.
    """
    if couplings is not None and check_couplings(couplings) != window.couplings:
        window = replace(window, couplings=couplings)
    lb, ub = fit_bounds(lower, upper, window.couplings)
    if int(n_starts) != n_starts or n_starts < 1:
        raise LoperInputError(f"n_starts must be an integer >= 1, got {n_starts}")
    if ci_dof is not None and (int(ci_dof) != ci_dof or ci_dof < 1):
        raise LoperInputError(f"ci_dof must be an integer >= 1, got {ci_dof}")
    starts = _starts(lb, ub, n_starts, seed, extra_starts)
    batch = ResidualBatch(window, lb, ub)
    if not 0 <= merge_tolerance < 1:
        raise LoperInputError(f"merge_tolerance must lie in [0, 1), got {merge_tolerance}")
    points, costs, converged, _ = multistart_lm(batch, starts, max_iterations, tolerance, merge_tolerance)
    costs = np.where(np.isfinite(costs), costs, np.inf)  # a start whose simulation diverged (e.g. a stiff ankle)
    if not np.any(np.isfinite(costs)):
        raise LoperInputError("identify_impedance: the simulation diverged from every start")
    best = int(np.argmin(costs))
    polish = _polish(batch, points[best], polish_max_evaluations)
    estimate = np.clip(polish.x, lb, ub)
    if float(np.sum(polish.fun**2)) > costs[best]:  # keep the better of the two (trf steps inside bounds)
        estimate = points[best]
    r, J = batch.residuals_and_jacobians(estimate[None])
    r, J = r[0], J[0]
    pe = prediction_error(window, estimate)
    success = bool(polish.status > 0)
    message = (
        polish.message
        if success
        else (
            f"not converged: multistart LM converged={bool(converged[best])}, "
            f"polish status {polish.status} ({polish.message})"
        )
    )
    sd, corr, dof = _parameter_sd_and_correlation(window, batch, estimate, r, J)
    ci_low, ci_high = bounded_interval(estimate, sd, dof if ci_dof is None else int(ci_dof), lb, ub)
    model = window.measured - pe
    vaf = variance_accounted_for(window.measured, model)
    return ImpedanceFit(
        estimate=estimate,
        cost=float(np.sum(r**2)),
        sum_sq_error_rad2=float(np.sum(pe**2)),
        ci95_low=ci_low,
        ci95_high=ci_high,
        sd=sd,
        ci_dof=int(dof if ci_dof is None else ci_dof),
        correlation=corr,
        vaf_pct=vaf,
        success=success,
        message=str(message),
        n_starts=len(starts),
        n_starts_at_best=starts_at_best(costs),
        n_simulations=batch.n_simulations,
        starts=starts,
        start_estimates=points,
        start_costs=costs,
        time_s=window.time_s,
        measured=window.measured,
        model=model,
        parameters=window.parameters,
    )


def _starts(
    lb: np.ndarray, ub: np.ndarray, n_starts: int, seed: int | np.random.SeedSequence | None, extra_starts
) -> np.ndarray:
    """The starts (k + n_starts, p) of the fit: ``extra_starts`` (k, p) clipped to the bounds ``lb``, ``ub``
    (p,), then ``n_starts`` drawn uniformly inside them (NumPy ``default_rng(seed)``). Extra starts of the six
    K and D alone, for a fit with couplings (p > 6), start the couplings at 0."""
    n = len(lb)
    rng = np.random.default_rng(seed)
    starts = rng.uniform(lb, ub, size=(int(n_starts), n))
    if extra_starts is not None:
        extra = np.atleast_2d(np.asarray(extra_starts, dtype=float))
        if extra.shape[1:] == (len(PARAMETERS),) and n > len(PARAMETERS):
            extra = np.hstack([extra, np.zeros((len(extra), n - len(PARAMETERS)))])
        if extra.shape[1:] != (n,) or not np.all(np.isfinite(extra)):
            raise LoperInputError(f"extra_starts must be finite with {n} values per row, got shape {extra.shape}")
        starts = np.vstack([np.clip(extra, lb, ub), starts])
    return starts


def _polish(batch: ResidualBatch, start: np.ndarray, max_evaluations: int):
    """SciPy's ``least_squares`` (trust-region reflective, inside the batch's bounds) from ``start`` (p,),
    with the batch's residuals and Jacobians, to machine precision or ``max_evaluations`` residual evaluations."""

    def fun(p):
        return batch.residuals(p[None])[0]

    def jac(p):
        return batch.residuals_and_jacobians(p[None])[1][0]

    return least_squares(
        fun,
        start,
        jac=jac,
        bounds=(batch.lb, batch.ub),
        method="trf",
        x_scale=batch.typical * 100,
        ftol=1e-14,
        xtol=1e-14,
        gtol=1e-14,
        max_nfev=int(max_evaluations),
    )


def _parameter_sd_and_correlation(
    window: PreparedWindow, batch: ResidualBatch, estimate: np.ndarray, r: np.ndarray, J: np.ndarray
) -> tuple[np.ndarray, np.ndarray, int]:
    """Standard deviations (p,; inf: no information) and correlation (p, p) of the parameters at ``estimate``
    from the residuals ``r`` (m,) and their Jacobian ``J`` (m, p), and the residuals' degrees of freedom.

    Without ``noise_cov``: white residual noise plus the uncertainty of the initial state, propagated
    (sandwich). With ``noise_cov``: the sandwich of the linearised estimator M = (W J)^+ W; ``noise_cov``
    holds the initial state's share already.
    """
    m = r.size
    n_par = J.shape[1]
    dof = max(m - n_par, 1)
    s2 = float(np.sum(r**2)) / dof
    JTJ = J.T @ J
    A = np.linalg.pinv(JTJ, rcond=1e-13)
    with np.errstate(divide="ignore", invalid="ignore"):
        if window.noise_cov is None:
            JG = J.T @ initial_state_jacobian(window, estimate)
            cov = s2 * A + A @ JG @ window.initial_state_cov @ JG.T @ A
        else:
            cov = sandwich_covariance(J, window.noise_cov, batch.weight)
        sd = np.sqrt(np.clip(np.diag(cov), 0, None))
        corr = cov / np.outer(sd, sd)
    rank = np.linalg.matrix_rank(JTJ, tol=1e-13 * np.max(np.abs(JTJ)) if np.any(JTJ) else None)
    if rank < n_par:
        sd = np.where(np.diag(JTJ) > 0, sd, np.inf)
    sd = np.where(np.isnan(sd), np.inf, sd)
    return sd, corr, dof
