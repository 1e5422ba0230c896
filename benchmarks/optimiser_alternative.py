"""The batched multistart Levenberg-Marquardt against SciPy's least_squares run from each start on its own.

Usage: python benchmarks/optimiser_alternative.py [n_cases]

On validation-study windows (random K/D combinations, without and with
noise) both optimisers start from the same 10 random points with the same
tolerance (config impedance.tolerance, 1e-6) and the same batched
forward-difference Jacobian; the best start of each is polished to 1e-14 as
the pipeline does. Prints the time per identification and how often each
ends more than 0.1 % above the other's cost.
"""

from __future__ import annotations

import sys
import time

import numpy as np
from scipy.optimize import least_squares

from loper_analysis.impedance.identification import (
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    identify_impedance,
)
from loper_analysis.impedance.identification.fit import ResidualBatch
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    impedance_grid,
    perturbed_trial,
    validation_window,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry


def per_start_least_squares(window, n_starts: int, seed: int, tol: float = 1e-6) -> float:
    """Cost (rad^2) of the best of ``n_starts`` independent trust-region-reflective fits, polished."""
    lb, ub = DEFAULT_LOWER, DEFAULT_UPPER
    batch = ResidualBatch(window, lb, ub)
    starts = np.random.default_rng(seed).uniform(lb, ub, size=(n_starts, 6))

    def fun(p):
        return batch.residuals(p[None])[0]

    def jac(p):
        return batch.residuals_and_jacobians(p[None])[1][0]

    fits = [
        least_squares(
            fun,
            s,
            jac=jac,
            bounds=(lb, ub),
            method="trf",
            x_scale=batch.typical * 100,
            ftol=tol,
            xtol=tol,
            gtol=tol,
            max_nfev=180,
        )
        for s in starts
    ]
    best = min(fits, key=lambda f: f.cost)
    polish = least_squares(
        fun,
        best.x,
        jac=jac,
        bounds=(lb, ub),
        method="trf",
        x_scale=batch.typical * 100,
        ftol=1e-14,
        xtol=1e-14,
        gtol=1e-14,
        max_nfev=200,
    )
    return float(np.sum(polish.fun**2))


def main(n_cases: int = 40) -> None:
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    settings = ValidationSettings()
    grid = impedance_grid(settings.stiffness_levels_nm_per_rad, settings.damping_levels_nms_per_rad)
    cases = np.random.default_rng(7).choice(len(grid), n_cases, replace=False)
    times = {"batched LM": [], "least_squares per start": []}
    worse = {"batched LM": 0, "least_squares per start": 0}
    for n, c in enumerate(cases):
        trial = perturbed_trial(params, grid[c], settings)
        rng = np.random.default_rng([settings.seed, int(c)])
        qu, qp = trial[1], trial[2]
        window = validation_window(
            params,
            settings,
            trial,
            qu + rng.uniform(-0.005, 0.005, qu.shape),
            qp + rng.uniform(-0.005, 0.005, qp.shape),
        )
        t0 = time.perf_counter()
        lm = identify_impedance(window, n_starts=10, seed=int(c)).cost
        t1 = time.perf_counter()
        trf = per_start_least_squares(window, 10, int(c))
        t2 = time.perf_counter()
        if n == 0:
            continue  # the first case loads the compiled kernels
        times["batched LM"].append(t1 - t0)
        times["least_squares per start"].append(t2 - t1)
        worse["batched LM"] += lm > trf * 1.001
        worse["least_squares per start"] += trf > lm * 1.001
    for name, v in times.items():
        v = np.array(v)
        print(
            f"{name:24s} one identification (10 starts, noise): median {1e3 * np.median(v):.0f} ms, "
            f"max {1e3 * v.max():.0f} ms, total {v.sum():.1f} s; ends > 0.1 % above the other in "
            f"{worse[name]} of {v.size} fits"
        )


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
