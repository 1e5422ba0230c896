"""The second rod at the coordinate level: how precisely the fit places each joint's K and D with the thigh rod
alone and with a second rod just above the ankle, on the validation study's simulated strides.

Usage: python benchmarks/two_rods_validation.py [--fits 200] [--strides 1 30]

For the study's hip (K 55 N·m/rad, D 3.5 N·m·s/rad), its knee (3, 0.1) and an ankle of 8 and 0.3, a stride is
pushed by the study's pulse at the thigh, or at the thigh and at the shank at once (85 % of the shank below the
knee, the same pulse), simulated by fine-step RK4 (the validation study's truth), and its coordinates get the
validation's uniform noise (0.01 rad or m peak to peak) divided by sqrt(n) for n averaged strides (the mean of n
strides' independent noise; stride-to-stride variability of the gait is not simulated here). Each design is fitted
``--fits`` times (noise draws seeded by the draw's number). Printed per design, stride count and parameter: the SD
and mean error of the estimates, the share within the study's tolerance (K: 10 % or 2 N·m/rad; D: 15 % or
0.05 N·m·s/rad) and the share of 95 % intervals that hold the truth.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from loper_analysis.constants import PARAMETERS  # noqa: E402
from loper_analysis.impedance.identification.validation import two_rod_trial, validation_window  # noqa: E402
from tests.impedance.identification.test_two_rods import STUDY_TRUTH, TWO_RODS  # noqa: E402
from tests.impedance.identification.validation_windows import SETTINGS, fit  # noqa: E402

DESIGNS = {"thigh rod": (1.0, 0.0), "both rods": (1.0, 1.0)}


def tolerance(truth: np.ndarray) -> np.ndarray:
    """The study's tolerance per parameter: K 10 % or 2 N·m/rad, D 15 % or 0.05 N·m·s/rad, whichever is larger."""
    k = np.maximum(0.10 * np.abs(truth[0::2]), 2.0)
    d = np.maximum(0.15 * np.abs(truth[1::2]), 0.05)
    return np.ravel(np.column_stack([k, d]))


def design_fits(thigh: float, shank: float, n_strides: int, n_fits: int) -> tuple[np.ndarray, ...]:
    """Estimates, interval lows and highs (n_fits, 6) of one design at noise / sqrt(n_strides)."""
    trial = two_rod_trial(TWO_RODS, STUDY_TRUTH, SETTINGS, shank, thigh)
    qu, qp = trial[1], trial[2]
    half = 0.5 * SETTINGS.noise_peak_to_peak / np.sqrt(n_strides)
    est, low, high = [], [], []
    for draw in range(n_fits):
        rng = np.random.default_rng([2024, n_strides, draw])
        window = validation_window(
            TWO_RODS,
            SETTINGS,
            trial[:6],
            qu + rng.uniform(-half, half, qu.shape),
            qp + rng.uniform(-half, half, qp.shape),
            shank_force_perturbed_n=trial[6],
        )
        result = fit(window, n_starts=3, seed=draw)
        est.append(result.estimate)
        low.append(result.ci95_low)
        high.append(result.ci95_high)
    return np.array(est), np.array(low), np.array(high)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fits", type=int, default=200, help="noise draws per design and stride count")
    parser.add_argument("--strides", type=int, nargs="+", default=[1, 30], help="averaged strides")
    args = parser.parse_args()
    tol = tolerance(STUDY_TRUTH)
    print("design      strides  parameter     SD    mean error  within tolerance  interval holds")
    for n in args.strides:
        for name, (thigh, shank) in DESIGNS.items():
            start = time.perf_counter()
            est, low, high = design_fits(thigh, shank, n, args.fits)
            err = est - STUDY_TRUTH
            within = np.mean(np.abs(err) <= tol, axis=0) * 100
            holds = np.mean((low <= STUDY_TRUTH) & (STUDY_TRUTH <= high), axis=0) * 100
            for i, p in enumerate(PARAMETERS):
                print(
                    f"{name:11s} {n:7d}  {p:9s} {est[:, i].std(ddof=1):9.3g}  {err[:, i].mean():10.3g}"
                    f"  {within[i]:15.1f} %  {holds[i]:13.1f} %"
                )
            print(f"  ({args.fits} fits in {time.perf_counter() - start:.0f} s)")


if __name__ == "__main__":
    main()
