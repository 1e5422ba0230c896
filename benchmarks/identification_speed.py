"""Wall time of one identification (10 random starts) on validation-study data.

Usage: python benchmarks/identification_speed.py [n_cases]
Prints per-condition median / max times of one identification (prepare_window + 10 starts), once with the
force at the robot rate (1000 Hz, as the pipeline fits) and once with the same force at the 128 Hz frames.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from loper_analysis.impedance.identification import identify_impedance, prepare_window
from loper_analysis.impedance.identification.validation import (
    ValidationSettings,
    impedance_grid,
    perturbed_trial,
)
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry


def main(n_cases: int = 40) -> None:
    params = segment_parameters_from_anthropometry(1.73, 64.9)
    s = ValidationSettings()
    grid = impedance_grid(s.stiffness_levels_nm_per_rad, s.damping_levels_nms_per_rad)
    cases = np.random.default_rng(7).choice(len(grid), n_cases, replace=False)
    times: dict[tuple[str, str], list[float]] = {}
    sims = []
    for n, c in enumerate(cases):
        t, qu, qp, fp, pel, tf = perturbed_trial(params, grid[c], s)
        f128 = np.stack([np.interp(t, tf, fp[:, j]) for j in range(2)], axis=-1)
        for cond in ("no_noise", "noise"):
            if cond == "noise":
                rng = np.random.default_rng(c)
                qu_m = qu + rng.uniform(-0.005, 0.005, qu.shape)
                qp_m = qp + rng.uniform(-0.005, 0.005, qp.shape)
            else:
                qu_m, qp_m = qu, qp
            for force in ("1000 Hz", "128 Hz"):
                extra = (
                    dict(force_perturbed_n=fp, force_time_s=tf) if force == "1000 Hz" else dict(force_perturbed_n=f128)
                )
                t0 = time.perf_counter()
                w = prepare_window(
                    t,
                    qu_m,
                    qp_m,
                    params,
                    s.onset_s,
                    pelvis_angle_unperturbed_rad=pel,
                    pelvis_angle_perturbed_rad=pel,
                    q_reference=qu,
                    **extra,
                )
                fit = identify_impedance(w, n_starts=10, seed=int(c))
                dt = time.perf_counter() - t0
                if n > 0:  # the first case includes loading the compiled kernels
                    times.setdefault((force, cond), []).append(dt)
                    sims.append(fit.n_simulations)
    for (force, cond), v in times.items():
        v = np.array(v)
        print(
            f"force {force:7s} {cond:9s} one identification (10 starts): median {np.median(v) * 1e3:.1f} ms, "
            f"max {v.max() * 1e3:.1f} ms over {len(v)} cases"
        )
    print(f"simulations per identification: median {np.median(sims):.0f}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 40)
