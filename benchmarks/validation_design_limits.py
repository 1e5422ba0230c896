"""What design would reach the study's validation figures, and how far the fit sits above the information limit.

Usage: python benchmarks/validation_design_limits.py [--draws N] [--seed S] [--no-fits]

1. Designs. The information limit of ``benchmarks/noise_information_limit.py`` (noise on the coordinates,
   initial state known) at all 729 combinations, for the study's design (128 Hz, window 25 ms before to
   250 ms after the onset), with the coordinates at 1000 Hz, with the whole swing as the window (toe-off to
   heel strike: 50 ms before to 550 ms after the onset) and with both. Per design: the root mean square of
   the bound over the 729 combinations (the smallest SD of errors pooled over them that unbiased estimates
   can have) and over the 64 whose every parameter is inside the fit's bounds, and the largest bound, each
   beside the study's SD as a ratio (below 1: the study's figure is within reach). About 45 s.
2. The fit against the limit. At the 8 combinations with every joint at 75 N·m/rad and 2 N·m·s/rad or at
   150 and 4 (inside the bounds, so that the bound applies to the fit), ``--draws`` noisy trials each, drawn
   and fitted as the validation study does (uniform noise on both strides' coordinates, the study's
   settings): the SD of the error over the draws, once with the initial state the fit takes from the noisy
   pre-onset samples (the validation study's fit) and once with the true initial state, each as a ratio to the
   bound at that combination. About 90 s with the default 100 draws (two fits per draw, one core);
   ``--no-fits`` leaves this part out.
"""

from __future__ import annotations

import argparse
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from noise_information_limit import (  # noqa: E402
    bounds_at,
    header,
    interior,
    row,
    study_sd,
)

from loper_analysis.constants import PARAMETERS  # noqa: E402
from loper_analysis.impedance.identification import identify_impedance  # noqa: E402
from loper_analysis.impedance.identification.validation import (  # noqa: E402
    ValidationSettings,
    impedance_grid,
    perturbed_trial,
    validation_window,
)
from loper_analysis.impedance.responses.response_window import ResponseWindow  # noqa: E402
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry  # noqa: E402

STUDY = ValidationSettings()
#: The whole simulated swing as the window: from toe-off (the onset is 50 ms after it) to the heel strike.
WHOLE_SWING = ResponseWindow(before_s=STUDY.onset_s, after_s=STUDY.swing_duration_s - STUDY.onset_s)
DESIGNS: dict[str, ValidationSettings] = {
    "study (128 Hz, -25..250 ms)": STUDY,
    "1000 Hz": replace(STUDY, sample_rate_hz=1000.0),
    "whole swing": replace(STUDY, window=WHOLE_SWING),
    "1000 Hz, whole swing": replace(STUDY, sample_rate_hz=1000.0, window=WHOLE_SWING),
}
#: Combinations of the fit's Monte Carlo: every joint at (75, 2) or at (150, 4).
FIT_TRUTHS = np.array(
    [sum(((75.0, 2.0) if b == "0" else (150.0, 4.0) for b in f"{i:03b}"), ()) for i in range(8)], dtype=float
)


def design_limits(params) -> None:
    """Part 1: the bound's root mean square and largest value per design, beside the study's SD."""
    study = study_sd()
    for name, settings in DESIGNS.items():
        t0 = time.perf_counter()
        grid = impedance_grid(settings.stiffness_levels_nm_per_rad, settings.damping_levels_nms_per_rad)
        bounds = bounds_at(params, settings, grid)
        inside = interior(grid, settings)
        rms_all = np.sqrt(np.mean(bounds**2, axis=0))
        rms_in = np.sqrt(np.mean(bounds[inside] ** 2, axis=0))
        print(f"\n{name} ({time.perf_counter() - t0:.0f} s)")
        print(header())
        print(row("bound, root mean square, all", rms_all))
        print(row("  / study SD", rms_all / study))
        print(row(f"bound, root mean square, {int(inside.sum())} inside", rms_in))
        print(row("  / study SD", rms_in / study))
        print(row("bound, largest", bounds.max(axis=0)))
        print(row("  / study SD", bounds.max(axis=0) / study))


def fit_errors(params, settings: ValidationSettings, truth: np.ndarray, draws: int, seed: int):
    """Errors (draws, 6) of the validation study's fit at ``truth`` over noisy draws: with the initial state from
    the noisy samples, and with the true initial state (the noise-free window's)."""
    trial = perturbed_trial(params, truth, settings)
    _, qu, qp = trial[:3]
    clean = validation_window(params, settings, trial)
    a = settings.noise_peak_to_peak / 2
    fit_options = dict(
        n_starts=settings.n_starts,
        lower=settings.lower,
        upper=settings.upper,
        tolerance=settings.tolerance,
        merge_tolerance=settings.merge_tolerance,
    )
    noisy_state, known_state = [], []
    for k in range(draws):
        rng = np.random.default_rng([seed, *truth.astype(int).tolist(), k])
        window = validation_window(
            params, settings, trial, qu + rng.uniform(-a, a, qu.shape), qp + rng.uniform(-a, a, qp.shape)
        )
        known = replace(
            window,
            initial_deviation=clean.initial_deviation,
            initial_rate=clean.initial_rate,
            initial_state_cov=np.zeros((8, 8)),
        )
        noisy_state.append(identify_impedance(window, seed=k, **fit_options).estimate - truth)
        known_state.append(identify_impedance(known, seed=k, **fit_options).estimate - truth)
    return np.array(noisy_state), np.array(known_state)


def fit_against_limit(params, draws: int, seed: int) -> None:
    """Part 2: the fit's SD over noisy draws at :data:`FIT_TRUTHS` against the bound there."""
    t0 = time.perf_counter()
    bounds = bounds_at(params, STUDY, FIT_TRUTHS)
    ratios_noisy, ratios_known = [], []
    print(f"\nthe fit at the study's design, {draws} noisy draws per combination: SD of the error / bound")
    print(header())
    for truth, bound in zip(FIT_TRUTHS, bounds):
        noisy, known = fit_errors(params, STUDY, truth, draws, seed)
        label = "/".join(f"{truth[2 * j]:.0f},{truth[2 * j + 1]:.0f}" for j in range(3))
        print(row(f"{label} bound", bound))
        print(row("  fit, initial state from the noisy data", noisy.std(axis=0, ddof=1) / bound))
        print(row("  fit, initial state known", known.std(axis=0, ddof=1) / bound))
        ratios_noisy.append(noisy.std(axis=0, ddof=1) / bound)
        ratios_known.append(known.std(axis=0, ddof=1) / bound)
    hip_knee = slice(0, 4)
    for name, r in (("initial state from the noisy data", ratios_noisy), ("initial state known", ratios_known)):
        r = np.array(r)[:, hip_knee]
        print(
            f"fit / bound, hip and knee, {name}: {r.min():.2f}-{r.max():.2f} "
            f"(per parameter: {', '.join(f'{p} {a:.2f}-{b:.2f}' for p, a, b in zip(PARAMETERS, r.min(0), r.max(0)))})"
        )
    print(f"({time.perf_counter() - t0:.0f} s)")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--draws", type=int, default=100, help="noisy draws per combination for the fits (default 100)")
    ap.add_argument("--seed", type=int, default=1, help="seed of the noise and the starts (default 1)")
    ap.add_argument("--no-fits", action="store_true", help="the designs' bounds only, no fits")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    params = segment_parameters_from_anthropometry(STUDY.subject_height_m, STUDY.subject_mass_kg)
    print("information limit with noise on the coordinates, initial state known; study SD:")
    print(header())
    print(row("study SD (noise)", study_sd()))
    design_limits(params)
    if not args.no_fits:
        fit_against_limit(params, args.draws, args.seed)
    print(f"\ntotal {time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()
