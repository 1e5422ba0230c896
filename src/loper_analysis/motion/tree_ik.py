"""Inverse kinematics on a model's kinematic tree: weighted least squares of marker distances, frame by frame.

Each frame minimises the objective of OpenSim's IK,

    sum_i w_i |p_i(q) - m_i|^2 / sum_i w_i  +  sum_c w_c (q_c - r_c)^2,

(markers ``i`` present in the frame with weights ``w_i``, coordinate tasks ``c`` with weights ``w_c`` and
values ``r_c``) by Gauss-Newton steps with Levenberg-Marquardt damping, starting from the previous frame's
solution (the first frame from the model's default pose, as OpenSim's solver assembles it). Marker positions
and their exact Jacobian come from :func:`loper_analysis.motion.kinematic_tree.tree_markers`, compiled, so a
frame costs a few passes over the tree instead of an optimiser's calls into OpenSim. A frame has converged
when its last step moved no coordinate by more than ``tree_step_tolerance`` (rad or m; config
``ik.tree_step_tolerance``). Locked coordinates stay at their default values and clamped ones within their
range, as in OpenSim.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import model_source
from loper_analysis.motion.kinematic_tree import KinematicTree, check_against_opensim, kinematic_tree, tree_markers

__all__ = ["MAX_ITERATIONS", "TreeSolution", "tree_inverse_kinematics", "tree_solution"]

#: Relative decrease of the objective below which a step counts as converged: the coordinates left moving are
#: ones the markers hardly determine (a forearm's pronation from markers on the hand's one side).
FLAT: float = 1e-10

#: Gauss-Newton steps a frame may take before it is reported as not converged.
MAX_ITERATIONS: int = 100


@dataclass(frozen=True)
class TreeSolution:
    """IK on the tree: ``coordinates`` (n_frames, nc) in rad or m in the tree's coordinate order,
    ``marker_errors_m`` (n_frames, n_markers) distance of each marker from its model marker (NaN where missing),
    ``iterations`` (n_frames,) Gauss-Newton steps taken (0 for frames not solved) and ``converged``
    (n_frames,) bool."""

    coordinates: np.ndarray
    marker_errors_m: np.ndarray
    iterations: np.ndarray
    converged: np.ndarray


def tree_inverse_kinematics(
    tree: KinematicTree,
    markers_m: np.ndarray,
    marker_names: list[str],
    weights: np.ndarray,
    *,
    frames: np.ndarray | None = None,
    task_coordinates: np.ndarray | None = None,
    task_weights: np.ndarray | None = None,
    task_values: np.ndarray | None = None,
    tree_step_tolerance: float = 1e-6,
    max_iterations: int = MAX_ITERATIONS,
) -> TreeSolution:
    """Solve IK for marker trajectories ``markers_m`` (n_frames, n_markers, 3) in m, NaN where missing.

    Parameters
    ----------
    tree : KinematicTree
        The model's tree (:func:`loper_analysis.motion.kinematic_tree.kinematic_tree`).
    marker_names : list of str
        The model marker of each column of ``markers_m``.
    weights : ndarray, shape (n_markers,)
        Marker weights (> 0).
    frames : ndarray of int, optional
        The frames to solve, in increasing order (default: all); the others are NaN.
    task_coordinates, task_weights, task_values : ndarray, shape (n_tasks,)
        Coordinate tasks: index into the tree's coordinates, weight, value (rad or m).
    tree_step_tolerance : float
        Convergence: a frame stops when its last step moved no coordinate by more than this (rad or m).
    max_iterations : int
        Steps per frame at the most.
    """
    index = {name: i for i, name in enumerate(tree.marker_names)}
    use = np.array([index[name] for name in marker_names], np.int64)
    X = np.ascontiguousarray(markers_m, float)
    n = X.shape[0]
    frames = np.arange(n) if frames is None else np.asarray(frames, np.int64)
    empty_i, empty_f = np.zeros(0, np.int64), np.zeros(0)
    tc = empty_i if task_coordinates is None else np.asarray(task_coordinates, np.int64)
    tw = empty_f if task_weights is None else np.asarray(task_weights, float)
    tv = empty_f if task_values is None else np.asarray(task_values, float)
    arrays = tree.kernel_arrays()
    Q, E, iterations = _solve_frames(
        (*arrays[:-2], tree.marker_body[use], np.ascontiguousarray(tree.marker_location_m[use])),
        X,
        np.asarray(weights, float),
        frames,
        tc,
        tw,
        tv,
        tree.default_q.copy(),
        ~(tree.locked | tree.dependent),
        tree.clamped,
        tree.range_q[:, 0].copy(),
        tree.range_q[:, 1].copy(),
        float(tree_step_tolerance),
        int(max_iterations),
    )
    converged = np.zeros(n, bool)
    converged[frames] = iterations[frames] <= max_iterations
    return TreeSolution(
        coordinates=Q, marker_errors_m=E, iterations=np.minimum(iterations, max_iterations), converged=converged
    )


@njit(cache=True)
def _cost(P, X, w, present, q, tc, tw, tv, w_total):  # pragma: no cover - compiled
    """The objective at marker positions ``P`` and coordinates ``q``."""
    f = 0.0
    for m in range(P.shape[0]):
        if present[m]:
            d0, d1, d2 = P[m, 0] - X[m, 0], P[m, 1] - X[m, 1], P[m, 2] - X[m, 2]
            f += w[m] * (d0 * d0 + d1 * d1 + d2 * d2)
    f /= w_total
    for t in range(tc.size):
        d = q[tc[t]] - tv[t]
        f += tw[t] * d * d
    return f


@njit(cache=True)
def _normal_equations(P, J, Xk, w, present, w_total, q, tc, tw, tv):  # pragma: no cover - compiled
    """Gauss-Newton's H = J'WJ (nc, nc) and gradient g = J'Wr (nc,) of the objective at one frame."""
    nc = q.size
    H = np.zeros((nc, nc))
    g = np.zeros(nc)
    for m in range(P.shape[0]):
        if not present[m]:
            continue
        s = w[m] / w_total
        for a in range(3):
            r = P[m, a] - Xk[m, a]
            for i in range(nc):
                Ji = J[m, a, i]
                if Ji == 0.0:
                    continue
                g[i] += s * Ji * r
                for j in range(i, nc):
                    H[i, j] += s * Ji * J[m, a, j]
    for t in range(tc.size):
        c = tc[t]
        g[c] += tw[t] * (q[c] - tv[t])
        H[c, c] += tw[t]
    for i in range(nc):
        for j in range(i):
            H[i, j] = H[j, i]
    return H, g


@njit(cache=True)
def _bounded_step(H, g, lam, free, clamped, lo, hi, q):  # pragma: no cover - compiled
    """The damped Gauss-Newton step (nc,) from ``q``: coordinates not ``free`` stay, and a clamped one that
    would leave its range [lo, hi] is held at the bound while the others are solved again (active set)."""
    nc = q.size
    scale = 0.0
    for i in range(nc):
        scale = max(scale, H[i, i])
    held = ~free
    target = np.zeros(nc)  # the step of each held coordinate
    for _ in range(nc + 1):
        A = H.copy()
        b = -g.copy()
        for i in range(nc):
            A[i, i] += lam * max(H[i, i], 1e-6 * scale) + 1e-12 * scale + 1e-300
        for j in range(nc):
            if held[j]:
                for i in range(nc):
                    b[i] -= A[i, j] * target[j]
        for i in range(nc):
            if held[i]:
                for j in range(nc):
                    A[i, j] = 0.0
                    A[j, i] = 0.0
                A[i, i] = 1.0
                b[i] = target[i]
        step = np.linalg.solve(A, b)
        outside = False
        for i in range(nc):
            if clamped[i] and not held[i] and (q[i] + step[i] < lo[i] or q[i] + step[i] > hi[i]):
                held[i] = True
                target[i] = (lo[i] if q[i] + step[i] < lo[i] else hi[i]) - q[i]
                outside = True
        if not outside:
            return step
    return step


@njit(cache=True)
def _solve_frames(
    arrays, X, w, frames, tc, tw, tv, q, free, clamped, lo, hi, step_tolerance, max_iterations
):  # pragma: no cover - compiled
    """Coordinates (n, nc), marker errors (n, nm) and steps per frame (n,; max_iterations + 1: not
    converged) of the frames ``frames`` of ``X``, starting from ``q`` (changed in place); ``arrays``: the
    tree's :meth:`~loper_analysis.motion.kinematic_tree.KinematicTree.kernel_arrays` for the markers of ``X``."""
    n, nm = X.shape[0], X.shape[1]
    nc = q.size
    Q = np.full((n, nc), np.nan)
    E = np.full((n, nm), np.nan)
    iterations = np.zeros(n, np.int64)
    P, J = np.empty((nm, 3)), np.zeros((nm, 3, nc))
    P_try, J_try = np.empty((nm, 3)), np.zeros((nm, 3, nc))
    present = np.zeros(nm, np.bool_)
    lam = 1e-3
    for k in frames:
        w_total = 0.0
        for m in range(nm):
            present[m] = np.isfinite(X[k, m, 0]) and np.isfinite(X[k, m, 1]) and np.isfinite(X[k, m, 2])
            if present[m]:
                w_total += w[m]
        J[:] = 0.0
        tree_markers(arrays, q, P, J)
        cost = _cost(P, X[k], w, present, q, tc, tw, tv, w_total)
        steps = 0
        while True:
            H, g = _normal_equations(P, J, X[k], w, present, w_total, q, tc, tw, tv)
            cost_before = cost
            while True:  # damp until the step lowers the objective (or is too small to matter)
                q_try = q + _bounded_step(H, g, lam, free, clamped, lo, hi, q)
                largest = np.max(np.abs(q_try - q))
                J_try[:] = 0.0
                tree_markers(arrays, q_try, P_try, J_try)
                cost_try = _cost(P_try, X[k], w, present, q_try, tc, tw, tv, w_total)
                steps += 1
                if cost_try <= cost or largest <= step_tolerance:
                    q[:], P[:], J[:], cost = q_try, P_try, J_try, cost_try
                    lam = max(lam / 10.0, 1e-9)
                    break
                lam = min(lam * 10.0, 1e12)
                if steps > max_iterations:
                    break
            if largest <= step_tolerance or steps > max_iterations or cost_before - cost <= FLAT * cost_before:
                break
        iterations[k] = steps
        Q[k] = q
        for m in range(nm):
            if present[m]:
                E[k, m] = np.sqrt(np.sum((P[m] - X[k, m]) ** 2))
    return Q, E, iterations


def tree_solution(
    model, t, X, labels, marker_weights, *, coordinate_tasks, frames, tree_step_tolerance, source
) -> tuple[np.ndarray, np.ndarray]:
    """IK on the kinematic tree of an ``opensim.Model``, in the terms of
    :func:`loper_analysis.motion.opensim_ik.opensim_solution`: coordinates (n_frames, n_coordinates) in
    coordinate-set order and each marker's distance error (n_frames, n_markers) in m, NaN outside ``frames``.

    Raises
    ------
    UnsupportedModel
        The tree does not reproduce the model's marker positions
        (:func:`loper_analysis.motion.kinematic_tree.check_against_opensim`).
    """
    tree = kinematic_tree(model)
    check_against_opensim(model, tree)
    index = {c: i for i, c in enumerate(tree.coordinate_names)}
    unknown = [c for c in coordinate_tasks or {} if c not in index]
    if unknown:
        where = f"{source}: " if source else ""
        raise LoperInputError(
            f"{where}coordinate task on '{unknown[0]}': not a coordinate of {model_source(model)}; "
            f"has {list(tree.coordinate_names)}"
        )
    tasks = [
        (index[c], w, tree.default_q[index[c]] if v is None else float(v))
        for c, (w, v) in (coordinate_tasks or {}).items()
    ]
    solution = tree_inverse_kinematics(
        tree,
        X,
        list(labels),
        np.array([float(marker_weights[mk]) for mk in labels]),
        frames=frames,
        task_coordinates=np.array([c for c, _, _ in tasks], np.int64),
        task_weights=np.array([w for _, w, _ in tasks], float),
        task_values=np.array([v for _, _, v in tasks], float),
        tree_step_tolerance=tree_step_tolerance,
    )
    return solution.coordinates, solution.marker_errors_m
