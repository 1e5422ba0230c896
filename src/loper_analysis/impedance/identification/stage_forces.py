"""The rod forces at the RK4 stages: how a sampled force reaches the fixed-step integration of the fit.

* :func:`per_step` - stage values at the stage times as the four stages of each step (plain RK4);
* :func:`step_stage_forces` - stage forces that give each step the exact response of a linear system to the force;
* :func:`stage_force_means` - a force's means over the Simpson cells of the stage times.

Used by :func:`loper_analysis.impedance.identification.window.prepare_window` (method: ``docs/identification.md``,
"The force at its own rate").
"""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

__all__ = ["per_step", "step_stage_forces", "stage_force_means"]


def per_step(stage: np.ndarray) -> np.ndarray:
    """Stage values (2 N + 1, 2) at :func:`~.window.stage_times_s` -> the force at the four stages of each step
    (N, 4, 2).

    Start, middle, middle, end: plain RK4 with the force evaluated at the stage times (the
    ``force_perturbed_n`` layout of :class:`~.window.PreparedWindow`).
    """
    return np.stack([stage[:-1:2], stage[1::2], stage[1::2], stage[2::2]], axis=1)


def step_stage_forces(
    force_time_s: np.ndarray, force_n: np.ndarray, start_s: float, step_s: float, n_steps: int
) -> np.ndarray:
    """Stage forces (n_steps, 4, 2) that give each RK4 step the exact response of a linear system to the force.

    RK4 on ``y' = A y + b F(t)`` adds per step of length h
    ``h/6 [(1 + hA + h²A²/2 + h³A³/4) F1 + (2 + hA + h²A²/2) F2 + (2 + hA) F3 + F4] b``;
    the exact forced response is ``sum_j A^j / j! R_j b`` with the moments
    ``R_j = int_0^h (h - s)^j F(s) ds``. Equating the powers of A up to the
    third, RK4's own order, gives ``F1 = 4 R3 / h^4``, ``F1 + F2 = 6 R2 / h^3``,
    ``F1 + F2 + F3 = 6 R1 / h^2`` and ``F1 + 2 F2 + 2 F3 + F4 = 6 R0 / h``: the
    step then carries the force's impulse and its timing within the step
    exactly, however fast its edges (a constant force gives F1 = .. = F4 = F).
    The force is the cubic spline (not-a-knot) through its samples ``force_n``
    (k, 2) at ``force_time_s`` (k,); the moments are exact (4-point
    Gauss-Legendre on every piece between samples and step boundaries).
    """
    tf = np.asarray(force_time_s, dtype=float)
    f = np.asarray(force_n, dtype=float)
    h = float(step_s)
    bounds = start_s + h * np.arange(n_steps + 1)
    inner = tf[(tf > bounds[0]) & (tf < bounds[-1])]
    edges = np.unique(np.concatenate([bounds, inner]))
    a, b = edges[:-1], edges[1:]
    keep = b - a > 1e-12 * h
    a, b = a[keep], b[keep]
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    step_of = np.clip(np.floor((mid - start_s) / h).astype(int), 0, n_steps - 1)
    nodes, weights = np.polynomial.legendre.leggauss(4)
    x = mid[:, None] + half[:, None] * nodes
    wq = half[:, None] * weights
    fx = CubicSpline(tf, f, axis=0)(x)  # (n_piece, 4, 2)
    r = bounds[step_of + 1][:, None] - x  # time to the step's end
    R = np.zeros((4, n_steps, 2))
    for j in range(4):
        np.add.at(R[j], step_of, np.sum((wq * r**j)[..., None] * fx, axis=1))
    F = np.empty((n_steps, 4, 2))
    F[:, 0] = 4.0 * R[3] / h**4
    F[:, 1] = 6.0 * R[2] / h**3 - F[:, 0]
    F[:, 2] = 6.0 * R[1] / h**2 - F[:, 0] - F[:, 1]
    F[:, 3] = 6.0 * R[0] / h - F[:, 0] - 2.0 * F[:, 1] - 2.0 * F[:, 2]
    return F


def stage_force_means(force_time_s: np.ndarray, force_n: np.ndarray, stage_time_s: np.ndarray) -> np.ndarray:
    """Means (n_stage, 2) of a sampled force over the Simpson cells of RK4 stage times.

    ``stage_time_s`` (2 N + 1,) are the RK4 stage times of N steps of length
    h, every h / 2 from the window start. RK4 weights a step's start, middle
    and end by 1/6, 4/6 and 1/6 of h; the cells ``[t - h/6, t + h/6]`` around
    a step boundary and ``[t - h/3, t + h/3]`` around a midpoint (clipped to
    the window) therefore tile the window, and the mean of the force over
    each cell makes every step's stage-weighted force equal the force's exact
    integral over the step. The force is the cubic spline (not-a-knot) through
    its samples ``force_n`` (k, 2) at ``force_time_s`` (k,), integrated exactly.
    """
    ts = np.asarray(stage_time_s, dtype=float)
    h = 2.0 * (ts[1] - ts[0])
    half = np.where(np.arange(len(ts)) % 2 == 0, h / 6.0, h / 3.0)
    lo = np.maximum(ts - half, ts[0])
    hi = np.minimum(ts + half, ts[-1])
    spline = CubicSpline(np.asarray(force_time_s, dtype=float), np.asarray(force_n, dtype=float), axis=0)
    integral = spline.antiderivative()
    return (integral(hi) - integral(lo)) / (hi - lo)[:, None]
