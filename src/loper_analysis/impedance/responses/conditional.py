"""The conditional counterfactual: a perturbed stride's unperturbed continuation, predicted from its pre-onset course.

The study compares each perturbed stride with *one* unperturbed stride, the most similar over 25 ms before
the onset (:mod:`.matching`); how that stride goes on differs from how the perturbed stride would have gone
on, and that difference is most of a fit's error. Here every unperturbed stride of the onset's trials is a
sample of the pair (pre-onset joint and pelvis angles ``x``, window ``y``), aligned at the perturbed stride's
delay after toe-off, and the unperturbed continuation of the perturbed stride is the conditional mean of ``y`` given its
own ``x``: a ridge regression on the candidates (Gaussian conditioning with the pre-onset covariance shrunk),

    y_hat(x) = y_mean + (x - x_mean)^T (Xc^T Xc + lam I)^-1 Xc^T Yc = sum_u w_u(x) y_u,

a weighted sum of the candidates' windows whose weights ``w`` (:func:`ridge_weights`) sum to 1. Every column
(joint angles, pelvis, force) is predicted with the same weights. The penalty ``lam`` is chosen by
leave-one-out over the candidates (:func:`loo_penalty`); each candidate predicted from the others
(:func:`loo_weights`) is a *null pair* of this counterfactual, the noise model of the fit.

* :func:`ridge_weights`, :func:`loo_weights`, :func:`loo_penalty` - the regression, on arrays;
* :class:`CandidatePool` - the unperturbed strides of a subject's trials at one onset, and their windows at
  any delay after toe-off;
* :func:`conditional_windows` - the predicted unperturbed windows of the perturbed strides;
* :func:`conditional_null_pairs` - the candidates' leave-one-out predictions;
* :func:`covariance_scale` - what the scatter of the pairs misses: the candidates' noise shared by all
  predictions.

Method and its checks: ``docs/identification.md`` (The counterfactual).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import bool_column, where
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses.native_force import finite_spans, force_vectors, rod_magnitudes
from loper_analysis.impedance.responses.sampling import SplineSampler
from loper_analysis.impedance.responses.windows import window_coordinates

__all__ = [
    "PENALTY_GRID",
    "MIN_CANDIDATES",
    "ridge_weights",
    "loo_weights",
    "loo_penalty",
    "CandidatePool",
    "conditional_windows",
    "conditional_null_pairs",
    "covariance_scale",
    "unit_scatter_variance",
    "shared_weight_terms",
]

#: Penalties tried by :func:`loo_penalty`, as fractions of the mean eigenvalue of ``Xc^T Xc``.
PENALTY_GRID: tuple[float, ...] = tuple(float(a) for a in np.logspace(-6, 1, 15))
#: Fewest unperturbed candidates a conditional prediction needs.
MIN_CANDIDATES: int = 10


def _penalty(Xc: np.ndarray, alpha: float) -> float:
    """The ridge penalty ``alpha`` x the mean eigenvalue of ``Xc^T Xc``."""
    return float(alpha) * float(np.sum(Xc**2)) / max(Xc.shape[1], 1)


def ridge_weights(x, X, alpha: float) -> np.ndarray:
    """Weights (n_targets, n) of the candidates in the ridge prediction at ``x``.

    ``x`` (n_targets, m) or (m,): the targets' regressors; ``X`` (n, m) the candidates'. With
    ``Xc = X - mean(X)`` and ``lam = alpha * trace(Xc^T Xc) / m``, the weights are
    ``1/n + (x - mean(X))^T (Xc^T Xc + lam I)^-1 Xc^T``: the prediction of any quantity ``Y`` (n, ...)
    of the candidates is ``w @ Y``. The weights of a target sum to 1 (the intercept is not shrunk), and
    at ``alpha`` -> 0 with ``n > m`` they give the least-squares prediction.
    """
    X = np.asarray(X, dtype=float)
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n, m = X.shape
    mean = X.mean(axis=0)
    Xc = X - mean
    A = Xc.T @ Xc + _penalty(Xc, alpha) * np.eye(m)
    B = np.linalg.solve(A, (x - mean).T)  # (m, n_targets)
    return 1.0 / n + (Xc @ B).T


def _hat(Xc: np.ndarray, alpha: float) -> np.ndarray:
    """Hat matrix (n, n) of the ridge fit with an unshrunk intercept."""
    n, m = Xc.shape
    u, s, _ = np.linalg.svd(Xc, full_matrices=False)
    shrink = s**2 / (s**2 + _penalty(Xc, alpha)) if s.size else s
    return np.full((n, n), 1.0 / n) + (u * shrink) @ u.T


def loo_weights(X, alpha: float) -> np.ndarray:
    """Weights (n, n) of each candidate's prediction from the *other* candidates (zero diagonal).

    Row ``i`` equals :func:`ridge_weights` at ``X[i]`` fitted without row ``i`` up to the penalty, which is
    kept at the one of all rows (the linear smoother's leave-one-out identity,
    ``(H_i - h_ii e_i) / (1 - h_ii)``). Rows sum to 1.
    """
    X = np.asarray(X, dtype=float)
    H = _hat(X - X.mean(axis=0), alpha)
    h = np.diag(H).copy()
    W = (H - np.diag(h)) / (1.0 - h)[:, None]
    return W


def loo_penalty(X, Y, alphas: Sequence[float] = PENALTY_GRID) -> float:
    """The penalty of :data:`PENALTY_GRID` (fraction of the mean eigenvalue) with the least leave-one-out error.

    ``X`` (n, m): the candidates' regressors; ``Y`` (n, q): what is predicted (e.g. the joint angles after
    the onset). The error is the sum of squared leave-one-out residuals ``(Y_i - Yhat_i) / (1 - h_ii)``.
    """
    X = np.asarray(X, dtype=float)
    Y = np.asarray(Y, dtype=float).reshape(len(X), -1)
    Xc = X - X.mean(axis=0)
    best, best_err = float(alphas[0]), np.inf
    for a in alphas:
        H = _hat(Xc, a)
        r = (Y - H @ Y) / (1.0 - np.diag(H))[:, None]
        err = float(np.sum(r**2))
        if err < best_err:
            best, best_err = float(a), err
    return best


def _scatter_variance(M: np.ndarray) -> float:
    """Expected sample variance (ddof 1) over rows of ``M @ e`` for white ``e`` of unit variance."""
    Mc = M - M.mean(axis=0)
    return float(np.sum(Mc**2)) / (M.shape[0] - 1)


def unit_scatter_variance(null_weights, null_keep=None) -> float:
    """Expected scatter (ddof 1) of the candidates' leave-one-out errors for white noise of unit variance.

    ``null_weights`` (N, N): :func:`loo_weights`; ``null_keep`` (N,) bool: the rows kept. A leave-one-out
    error is ``e_i - S_i @ e``, so its variance exceeds the noise's by ``|S_i|^2``; the scatter of the kept
    errors about their mean is this factor times the noise's variance.
    """
    S = np.asarray(null_weights, dtype=float)
    M = np.eye(S.shape[0]) - S
    if null_keep is not None:
        M = M[np.asarray(null_keep, dtype=bool)]
    return _scatter_variance(M)


def shared_weight_terms(weights) -> tuple[float, float]:
    """``(|mu|^2, tr Sigma)`` of the prediction weights (n_pairs, N) over the N candidates.

    ``mu`` is their mean and ``Sigma`` their covariance over the pairs (ddof 1); for ``n`` pairs drawn
    like these the mean weight vector has ``E |w_mean|^2 = |mu|^2 + tr Sigma / n``, so white noise of
    variance ``s^2`` on every stride gives the mean of ``n`` pairs' counterfactual errors the variance
    ``s^2 ((1 + tr Sigma) / n + |mu|^2)``: the candidates' share does not average out
    (:func:`covariance_scale`).
    """
    W = np.atleast_2d(np.asarray(weights, dtype=float))
    n = W.shape[0]
    w_mean = W.mean(axis=0)
    spread = float(np.sum((W - w_mean) ** 2)) / (n - 1) if n > 1 else 0.0
    return max(float(w_mean @ w_mean) - spread / n, 0.0), spread


def covariance_scale(weights, null_weights=None, null_keep=None) -> float:
    """Factor by which the covariance from the pairs' scatter / n_pairs understates that of their mean.

    ``weights`` (n_pairs, N): each averaged pair's prediction weights over the N candidates. With white
    noise (variance s^2) on every stride, pair ``p``'s counterfactual error is ``e_p - w_p @ e_cand``; the
    candidates' noise is shared by all predictions, so the mean of the pairs has variance
    ``s^2 (1 / n_pairs + |w_mean|^2)`` while the scatter of the pairs about their mean (ddof 1) shows
    ``s^2 (1 + n_pairs (mean |w_p|^2 - |w_mean|^2) / (n_pairs - 1))``. The factor is the first over the
    second / n_pairs (1 when every pair has its own candidate, as a distinct matched stride).

    ``null_weights`` (N, N): when the covariance comes from the scatter of the candidates' leave-one-out
    predictions instead (:func:`loo_weights`, rows ``null_keep`` kept), their errors are ``(I - S) e``
    and the denominator is their expected scatter.
    """
    W = np.atleast_2d(np.asarray(weights, dtype=float))
    n = W.shape[0]
    w_mean = W.mean(axis=0)
    target = (1.0 + n * float(w_mean @ w_mean)) / n
    if null_weights is None:
        return target / (_scatter_variance(np.hstack([np.eye(n), -W])) / n)
    return target / (unit_scatter_variance(null_weights, null_keep) / n)


# --------------------------------------------------------------------------- the candidates


@dataclass
class _PoolTrial:
    name: str
    sampler: SplineSampler
    toe_off_s: np.ndarray
    end_s: np.ndarray
    stride: np.ndarray
    native: tuple | None  # (robot times s, magnitude N (n,) or (n, 2), frame times s, direction (n, 2 per rod))
    native_step_s: float = 0.0  # the robot's sample interval (s)


class CandidatePool:
    """The unperturbed strides of a subject's trials at one onset, windowed at any delay after toe-off.

    Parameters
    ----------
    trials : sequence of (name, time_s, columns, strides, native)
        Per trial: its name; frame times (s); the columns to window (name -> (n_frames,) or
        (n_frames, k), e.g. ``joints`` (rad), ``pelvis_angle`` (rad), ``pelvis_x`` (m), ``force`` (N),
        ``force_vector`` (N)); its stride table (``stride``, ``toe_off_s``, ``end_s``, ``perturbed``,
        ``removed``); and None or ``(robot_table, direction)``: the force at the robot rate (``time_s``,
        ``force_measured_n``, and ``shank_force_measured_n`` with a second rod) and the rods' direction on the
        frames (n_frames, 2 per rod).
    start_s, end_s : float
        The window relative to the anchor (s), ``start_s <= 0 <= end_s``.
    rate_hz : float
        Grid rate (Hz).
    within_swing : bool
        A candidate's window must end before its own heel strike (default), as a perturbed stride's must
        (:func:`loper_analysis.impedance.responses.matching.too_short`): the pool then holds the strides whose swing
        could have held the window, as the kept perturbed strides' did. Without it, at a late onset the pool
        mixes in shorter swings, whose windows run into the next stance, and the predictions of the kept
        (longer) swings are biased.

    Candidates are the strides neither perturbed nor removed; at a given delay a candidate counts when its
    window lies in one run of finite frames of every column (and inside the robot log) and, with
    ``within_swing``, ends before its own heel strike.
    """

    def __init__(self, trials, start_s: float, end_s: float, rate_hz: float, within_swing: bool = True):
        self.grid = window_times_s(-start_s, end_s, rate_hz)
        self.pre = self.grid <= 1e-9
        self.within_swing = within_swing
        self.keys: list[str] = []
        self.shapes: list[tuple[int, ...]] = []
        self.trials: list[_PoolTrial] = []
        self.force_width = 2  # force components at the robot rate: 2 per rod
        for name, t, columns, strides, native in trials:
            if not self.keys:
                self.keys = list(columns)
                self.shapes = [np.asarray(columns[k]).shape[1:] for k in self.keys]
            stacked = np.concatenate([np.asarray(columns[k], float).reshape(len(t), -1) for k in self.keys], axis=1)
            perturbed = bool_column(strides, "perturbed", name, what="strides")
            removed = bool_column(strides, "removed", name, what="strides")
            keep = ~perturbed & ~removed
            nat = None
            if native is not None:
                table, direction = native
                self.force_width = int(np.shape(direction)[1])
                nat = (
                    table["time_s"].to_numpy(float),
                    rod_magnitudes(table, direction, name),
                    np.asarray(t, float),
                    np.asarray(direction, float),
                )
            self.trials.append(
                _PoolTrial(
                    name,
                    SplineSampler(np.asarray(t, float), stacked),
                    strides["toe_off_s"].to_numpy(float)[keep],
                    strides["end_s"].to_numpy(float)[keep],
                    strides["stride"].to_numpy()[keep],
                    nat,
                    float(np.median(np.diff(nat[0]))) if nat is not None else 0.0,
                )
            )

    @property
    def size(self) -> int:
        """Candidate strides in all trials (before the window's check)."""
        return int(sum(tr.toe_off_s.size for tr in self.trials))

    def windows(self, delay_s: float, native_grid=None) -> tuple[dict, np.ndarray | None, list, np.ndarray]:
        """Windows of the candidates anchored ``delay_s`` after their toe-off.

        Returns the columns (name -> (n_ok, n_grid, ...)), the force vectors at the robot rate on
        ``native_grid`` (s, relative; (n_ok, n_native, 2 per rod) N) or None, (trial, stride) of each window and its
        index among all :attr:`size` candidates.
        """
        parts, native, ids, index = [], [], [], []
        offset = 0
        for tr in self.trials:
            first, offset = offset, offset + tr.toe_off_s.size
            anchors = tr.toe_off_s + delay_s
            lo, hi = anchors + self.grid[0], anchors + self.grid[-1]
            runs = tr.sampler.run(lo, hi)
            ok = runs >= 0
            if self.within_swing:
                ok &= hi <= tr.end_s + tr.sampler.tol
            if native_grid is not None:
                tn, fm, tf, _ = tr.native
                step = tr.native_step_s
                ok &= (lo >= max(tn[0], tf[0]) - 1e-9) & (hi <= min(tn[-1], tf[-1]) + 1e-9)
                ok &= finite_spans(tn, fm if fm.ndim == 1 else fm.sum(axis=1), lo - step, hi + step)
            if not ok.any():
                continue
            targets = anchors[ok, None] + self.grid
            parts.append(tr.sampler(targets, runs[ok]))
            if native_grid is not None:
                native.append(force_vectors(anchors[ok, None] + np.asarray(native_grid, float), *tr.native))
            ids.extend((tr.name, int(s)) for s in tr.stride[ok])
            index.extend((first + np.flatnonzero(ok)).tolist())
        stacked = np.concatenate(parts) if parts else np.empty((0, self.grid.size, sum(_width(s) for s in self.shapes)))
        out, c = {}, 0
        for key, shape in zip(self.keys, self.shapes):
            w = _width(shape)
            out[key] = stacked[..., c : c + w].reshape(stacked.shape[:2] + shape)
            c += w
        nat = None
        if native_grid is not None:
            nat = np.concatenate(native) if native else np.empty((0, len(native_grid), self.force_width))
        return out, nat, ids, np.asarray(index, dtype=np.int64)

    def regressors(self, windows: Mapping[str, np.ndarray]) -> np.ndarray:
        """The regressors of windows: the pre-onset samples of the joint angles (n, n_grid, 3) and the pelvis
        angle (n, n_grid), rad, flattened (n, m)."""
        j, pel = windows["joints"][:, self.pre], windows["pelvis_angle"][:, self.pre]
        return np.concatenate([j.reshape(j.shape[0], j.shape[1] * j.shape[2]), pel], axis=1)


def _width(shape: tuple[int, ...]) -> int:
    return int(np.prod(shape)) if shape else 1


def conditional_windows(
    pool: CandidatePool,
    delays_s,
    perturbed: Mapping[str, np.ndarray],
    alpha: float,
    native_grid=None,
    source: str = "",
    labels: Sequence[str] = (),
) -> tuple[dict, np.ndarray | None, np.ndarray, list[str]]:
    """The predicted unperturbed windows of perturbed strides.

    Parameters
    ----------
    pool : CandidatePool
    delays_s : (n_p,) each perturbed stride's onset after its toe-off (s): the candidates' anchor.
    perturbed : the perturbed strides' windows: ``joints`` (n_p, n_grid, 3) and ``pelvis_angle`` (n_p, n_grid), rad.
    alpha : the ridge penalty (:func:`loo_penalty`).
    native_grid : relative times (s) of the force at the robot rate, or None.
    source : names the subject in messages; ``labels``: names each perturbed stride in them.

    Returns
    -------
    columns : name -> (n_p, n_grid, ...), the predicted windows (NaN rows for strides without a prediction);
    native : (n_p, n_native, 2 per rod) or None;
    weights : (n_p, pool.size) each stride's weights over all the pool's candidates (0 for those whose window
        leaves the data; a row of zeros without a prediction);
    missing : per stride the reason it has no prediction ("" otherwise).
    """
    delays = np.asarray(delays_s, dtype=float)
    x = pool.regressors({k: np.asarray(perturbed[k], dtype=float) for k in ("joints", "pelvis_angle")})
    out = {k: np.full((delays.size, pool.grid.size) + shape, np.nan) for k, shape in zip(pool.keys, pool.shapes)}
    native = None if native_grid is None else np.full((delays.size, len(native_grid), pool.force_width), np.nan)
    weights, missing = np.zeros((delays.size, pool.size)), []
    cache: dict[float, tuple] = {}
    for i, d in enumerate(delays):
        key = round(float(d), 9)
        if key not in cache:
            cache[key] = pool.windows(float(d), native_grid)
        cols, nat, _, index = cache[key]
        n = len(cols["joints"])
        if n < MIN_CANDIDATES:
            label = labels[i] if i < len(labels) else f"perturbed stride {i}"
            missing.append(
                f"{where(source)}{label}: {n} unperturbed candidate(s) cover the window at {d * 1e3:.1f} ms "
                f"after toe-off, fewer than {MIN_CANDIDATES}"
            )
            continue
        w = ridge_weights(x[i], pool.regressors(cols), alpha)[0]
        for k, v in cols.items():
            out[k][i] = np.tensordot(w, v, axes=1)
        if native is not None:
            native[i] = np.tensordot(w, nat, axes=1)
        weights[i, index] = w
        missing.append("")
    return out, native, weights, missing


def conditional_null_pairs(pool: CandidatePool, delay_s: float, alpha: float | None = None, source: str = "") -> dict:
    """Each candidate at ``delay_s`` after toe-off and its prediction from the other candidates.

    The windows are those of :meth:`CandidatePool.windows`; the predictions use :func:`loo_weights` with
    ``alpha`` (None: :func:`loo_penalty` on the joint angles after the anchor). Returns ``own`` and
    ``predicted`` (name -> (n, n_grid, ...)), ``alpha``, ``weights`` (n, n) and ``ids`` ((trial, stride)).

    Raises
    ------
    LoperInputError
        Fewer than :data:`MIN_CANDIDATES` candidates cover the window (naming the subject).
    """
    cols, _, ids, _ = pool.windows(float(delay_s))
    n = len(ids)
    if n < MIN_CANDIDATES:
        raise LoperInputError(
            f"{where(source)}conditional counterfactual: {n} unperturbed stride(s) cover the window at "
            f"{delay_s * 1e3:.1f} ms after toe-off, fewer than {MIN_CANDIDATES}"
        )
    X = pool.regressors(cols)
    if alpha is None:
        alpha = loo_penalty(X, cols["joints"][:, ~pool.pre].reshape(n, -1))
    W = loo_weights(X, alpha)
    predicted = {k: np.tensordot(W, v, axes=1) for k, v in cols.items()}
    return {"own": cols, "predicted": predicted, "alpha": float(alpha), "weights": W, "ids": ids}


def conditional_null_pair_windows(null: dict, time_s, before_s: float, after_s: float, keep) -> dict:
    """:func:`conditional_null_pairs` in the format of :func:`loper_analysis.impedance.responses.null_pair_windows`.

    ``null``: the candidates' own windows and their predictions; ``time_s`` the grid relative to the anchor
    (s); ``keep`` (n,) bool: the pairs the IQR rule kept (:func:`loper_analysis.impedance.responses.window_outliers`
    on ``-before_s .. after_s``). ``covariance_scale``: :func:`covariance_scale` of the kept pairs'
    leave-one-out weights (the factor for the null pairs' scatter, ``null["scale_of"]`` the perturbed
    strides' weights when given).
    """
    keep = np.asarray(keep, dtype=bool)
    out: dict = {"time_s": np.asarray(time_s, float)}
    for what, part in (("perturbed", null["own"]), ("unperturbed", null["predicted"])):
        j, pel, x = (part[k][keep] for k in ("joints", "pelvis_angle", "pelvis_x"))
        out[f"q_{what}"] = window_coordinates(j, pel, x)
        out[f"pelvis_angle_{what}_rad"] = pel
    out["n_pairs"], out["n_outliers"] = int(keep.sum()), int((~keep).sum())
    out["trial_deviation_rad"], out["trials_left_out"] = {}, {}
    out["alpha"] = null["alpha"]
    return out
