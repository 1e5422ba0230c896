"""Why one pilot predicts another SD than the next: the projection found from each trial's own null pairs.

Usage: nice -n 10 python benchmarks/planner_spread.py [--trials 16] [--onset-ms 175] [--seed 2024]
                                                      [--replicates 200] [--fit]

``--trials`` coordinate-level experiments of one subject on the lab of ``config/config.yaml`` (the same
experiments as ``benchmarks/planner_check.py``: one trial with the device, perturbed every 3-5 strides at the
onset, 60 perturbed strides; :func:`loper_analysis.synthetic.coordinate_trials.perturbation_experiment`) are
each planned as a pilot with the conditional counterfactual. For every trial the script takes the
per-stride SD of every K and D from the sandwich ``M C M^T`` of its null pairs' errors (linearised at the
truth), three ways (a fourth with ``--fit``):

* ``own``: with the projection found from the trial's own null pairs (what the planner does);
* ``fixed``: with the projection found from the first trial's null pairs, the same for all;
* ``bootstrap``: per trial, the SD over ``--replicates`` draws (with replacement) of its null pairs, the
  projection found anew in each draw, of the log of the predicted SD: how far one pilot can tell its own
  prediction varies;
* with ``--fit`` also the planner's whole prediction (:func:`conditional_stride_covariance`) at the trial's
  own fit of its perturbed strides and at the truth (10 s per trial more).

Prints, per parameter, the SD over the trials of the log of the predicted SD (about its coefficient of
variation) for ``own`` and ``fixed``, the mean ``bootstrap`` spread, the spread of the weight factor
``(1 + P |mu|^2) / v`` and, with ``--fit``, the correlation between the predictions at the estimate and at the truth.
With 16 trials the spread over trials is known to about ±35 % (95 %).
"""

from __future__ import annotations

import argparse
import logging
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))
from planner_check import ANGLE_NOISE_SD_RAD, HEIGHT_M, MASS_KG, TRUTH, estimates, lab  # noqa: E402

from loper_analysis.constants import PARAMETERS  # noqa: E402
from loper_analysis.impedance.identification import nuisance_projection, null_pair_errors, response_jacobian  # noqa: E402
from loper_analysis.impedance.identification.impedance import IdentificationSettings, fit_onset  # noqa: E402
from loper_analysis.impedance.responses import ResponseSettings  # noqa: E402
from loper_analysis.impedance.responses.conditional import shared_weight_terms  # noqa: E402
from loper_analysis.planning.covariance import conditional_stride_covariance
from loper_analysis.planning.inputs import pilot_onset_series  # noqa: E402
from loper_analysis.planning.precision import planning_window  # noqa: E402
from loper_analysis.planning.window import PlanSettings
from loper_analysis.report.markdown import markdown_table  # noqa: E402
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry  # noqa: E402
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment  # noqa: E402

N_STRIDES = 60


def log_sd(errors: np.ndarray, jacobian: np.ndarray, projection: np.ndarray) -> np.ndarray:
    """Log of the per-stride SD (p,) of the projected fit's estimate: the sandwich of ``errors`` (M, m)."""
    WJ = projection @ jacobian
    effect = (errors - errors.mean(axis=0)) @ (np.linalg.pinv(WJ.T @ WJ, rcond=1e-13) @ WJ.T @ projection).T
    return 0.5 * np.log(np.mean(effect**2, axis=0))


def bootstrap_spread(
    errors: np.ndarray, jacobian: np.ndarray, n_components: int, rng: np.random.Generator, replicates: int
) -> np.ndarray:
    """SD (p,) over ``replicates`` draws of the null pairs of the log SD, the projection found in each draw."""
    n = errors.shape[0]
    draws = []
    for _ in range(replicates):
        rows = errors[rng.integers(0, n, n)]
        draws.append(log_sd(rows, jacobian, nuisance_projection(rows, n_components)))
    return np.std(draws, axis=0, ddof=1)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trials", type=int, default=16)
    ap.add_argument("--onset-ms", type=int, default=175, choices=sorted(TRUTH))
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--replicates", type=int, default=200)
    ap.add_argument("--fit", action="store_true", help="also plan at each trial's own fit (10 s per trial)")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    logging.disable(logging.WARNING)
    t0 = time.perf_counter()
    truth = np.array(TRUTH[args.onset_ms])
    params = segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)
    response = ResponseSettings(counterfactual="conditional")
    plan = PlanSettings()
    r = plan.null_pair_components
    lab_kwargs = lab(None, args.seed, args.onset_ms, truth)
    rng = np.random.default_rng(args.seed)
    ident = IdentificationSettings(n_starts=10, seed=args.seed)  # the pipeline's fit, for --fit
    own, fixed, boot, weight, at_fit, at_truth = [], [], [], [], [], []
    first_projection = None
    for k in range(1, args.trials + 1):
        full, cut = perturbation_experiment(
            [args.seed, k],
            params,
            HEIGHT_M,
            args.onset_ms,
            truth,
            [N_STRIDES],
            angle_noise_sd_rad=ANGLE_NOISE_SD_RAD,
            **lab_kwargs,
        )
        series = pilot_onset_series([full], args.onset_ms, response)
        null, pairs = series["null_pairs"], series["pairs"]
        window = planning_window(null, params, plan)
        J = response_jacobian(window, truth, plan.lower, plan.upper)
        E = null_pair_errors(window, truth, null)
        W = nuisance_projection(E, r)
        first_projection = W if first_projection is None else first_projection
        own.append(log_sd(E, J, W))
        fixed.append(log_sd(E, J, first_projection))
        boot.append(bootstrap_spread(E, J, r, rng, args.replicates))
        mu2, _ = shared_weight_terms(pairs["prediction_weights"])
        weight.append((1.0 + pairs["n_pairs"] * mu2) / float(null["unit_scatter_variance"]))
        if args.fit:
            fit = fit_onset([cut[N_STRIDES]], params, args.onset_ms, f"T{k}", None, [full], response, ident)
            planned = np.clip(estimates(fit.rows), ident.lower, ident.upper)
            at_fit.append(conditional_stride_covariance(series, params, planned).sd)
            at_truth.append(conditional_stride_covariance(series, params, truth).sd)
        print(f"  trial {k}: {E.shape[0]} null pairs, {pairs['n_pairs']} perturbed, {time.perf_counter() - t0:.0f} s")
    rows = {
        "parameter": list(PARAMETERS),
        "own_projection": np.std(own, axis=0, ddof=1),
        "fixed_projection": np.std(fixed, axis=0, ddof=1),
        "bootstrap_of_one_pilot": np.mean(boot, axis=0),
    }
    if args.fit:
        a, b = np.array(at_fit), np.array(at_truth)
        rows["corr_at_fit_vs_truth"] = [np.corrcoef(a[:, i], b[:, i])[0, 1] for i in range(6)]
    print(
        f"onset {args.onset_ms} ms, {args.trials} trials of {N_STRIDES} perturbed strides, "
        f"{time.perf_counter() - t0:.0f} s; SD over trials of the log of the predicted SD per stride:"
    )
    print(markdown_table(pd.DataFrame(rows).round(3)))
    spread = np.std(np.log(weight), ddof=1) / 2  # on the SD: half that of the variance's log
    print(f"weight factor (1 + P |mu|^2) / v: SD over trials of the log of its root {spread:.3f}")


if __name__ == "__main__":
    main()
