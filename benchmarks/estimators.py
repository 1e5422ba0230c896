"""The study's matched stride against the conditional counterfactual, on the same simulated subjects.

Usage: python benchmarks/estimators.py [--subjects N] [--first K] [--jobs J] [--seed S] [--ik-noise-scale X]
                                       [--keep FILE] [--configfile FILE ...] [--tables FILE ...]
                                       [--estimators NAME ...]

N synthetic subjects with the study-level lab, at the default design (``config/config.yaml``: 2 trials of 45 s
per onset) or, with ``--configfile config/paper.yaml``, the study's (4-minute trials), simulated once and fitted
at the coordinate level (as ``benchmarks/ci_coverage.py --mode coordinates``) with each
estimator of :data:`ESTIMATORS`: ``matched_stride``, the study's method (the one most similar unperturbed stride, the
fit of the mean response, intervals from the perturbed pairs' scatter), and ``conditional``, the default (the
stride's own continuation predicted from its pre-onset course by all unperturbed strides, the fit allowing for
what averaging the pairs does to the model's response, intervals from its cross-validated null pairs).
``--estimators`` fits with some only (their rows can be joined with ``--tables`` later).

Prints, per estimator and parameter (hip/knee K and D) over all fitted rows of the three onsets (``ok`` or
``not_identifiable``): fits, RMSE, mean error and its ratio to the error's SD (a bias beyond a quarter of the
scatter shows here), the fits within tolerance and the intervals that hold the truth (with its binomial 95 %
interval), the rows ``ok`` (their joint's K and D judged informative) and how many of their intervals miss the
truth; then the same per onset; then the RMSE ratio conditional / matched stride.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ci_coverage import binomial_interval, run_coordinates, study_lab_config  # noqa: E402

from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE  # noqa: E402
from loper_analysis.report.markdown import markdown_table  # noqa: E402

#: (name, impedance.counterfactual, impedance.interval_scatter, impedance.averaging_correction):
#: the study's method (its matched stride, the fit of the mean, intervals from the perturbed pairs' scatter) and the
#: default (the conditional counterfactual, the averaging term, intervals from its cross-validated null pairs).
ESTIMATORS = (
    ("matched_stride", "matched_stride", "perturbed_pairs", False),
    ("conditional", "conditional", "cross_validated_null_pairs", True),
)
UNITS = {"K": "nm_per_rad", "D": "nms_per_rad"}


def estimator_table(rows: pd.DataFrame, by_onset: bool = False) -> pd.DataFrame:
    """Per estimator (and onset) and hip/knee K and D: fits, RMSE, mean error, within tolerance, coverage."""
    fitted = rows[rows["status"].isin(["ok", "not_identifiable"]) & rows["joint"].isin(["hip", "knee"])]
    keys = ["estimator", "onset_ms", "joint"] if by_onset else ["estimator", "joint"]
    out = []
    for key, g in fitted.groupby(keys, sort=False):
        for p, unit in UNITS.items():
            err = g[f"{p}_error_{unit}"].to_numpy(float)
            true = g[f"{p}_true_{unit}"].to_numpy(float)
            low, high = g[f"{p}_ci95_low_{unit}"].to_numpy(float), g[f"{p}_ci95_high_{unit}"].to_numpy(float)
            rel, ab = TRUTH_TOLERANCE[p]
            ok = (g["status"] == "ok").to_numpy()
            inside = (true >= low) & (true <= high)
            held = int(np.sum(inside))
            lo, hi = binomial_interval(held, err.size)
            sd = float(np.std(err, ddof=1)) if err.size > 1 else np.nan
            row = dict(zip(keys, key))
            out.append(
                {
                    **{k: v for k, v in row.items() if k != "joint"},
                    "parameter": f"{p}_{row['joint']}",
                    "fits": err.size,
                    "rmse": float(np.sqrt(np.mean(err**2))),
                    "mean_error": float(np.mean(err)),
                    "mean_over_sd": float(np.mean(err)) / sd if sd > 0 else np.nan,
                    "within_tolerance": int(np.sum(np.abs(err) <= np.maximum(rel * np.abs(true), ab))),
                    "truth_in_ci95": held,
                    "coverage": f"{held / err.size:.2f} [{lo:.2f}, {hi:.2f}]",
                    "ok": int(ok.sum()),
                    "ok_ci95_misses_truth": int(np.sum(ok & ~inside)),
                }
            )
    return pd.DataFrame(out)


def rmse_ratio(table: pd.DataFrame) -> pd.DataFrame:
    """RMSE of the conditional counterfactual over that of the matched stride, per parameter (empty unless both
    were fitted)."""
    wide = table.pivot(index="parameter", columns="estimator", values="rmse")
    if not {"conditional", "matched_stride"} <= set(wide.columns):
        return pd.DataFrame(columns=["parameter", "rmse_ratio"])
    return (wide["conditional"] / wide["matched_stride"]).rename("rmse_ratio").reset_index()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=34)
    ap.add_argument("--first", type=int, default=1, help="number of the first subject (C001: 1)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--ik-noise-scale", type=float, default=1.0, help="IK-like noise, times the chain's (0: none)")
    ap.add_argument("--keep", type=Path, help="write every fit's row here (TSV)")
    ap.add_argument("--tables", type=Path, nargs="+", help="no fits: the tables of rows kept by earlier runs")
    ap.add_argument("--configfile", nargs="+", default=[], help="config files layered over config/config.yaml")
    ap.add_argument(
        "--estimators", nargs="+", choices=[e[0] for e in ESTIMATORS], help="fit with these only (default: all)"
    )
    args = ap.parse_args()
    config = study_lab_config(args.configfile, args.seed)
    names = [f"C{k:03d}" for k in range(args.first, args.first + args.subjects)]
    t0 = time.perf_counter()
    if args.tables:
        rows = pd.concat([pd.read_csv(f, sep="\t") for f in args.tables], ignore_index=True)
        names = sorted(set(rows["subject"]))
        print(f"python benchmarks/estimators.py --tables {' '.join(map(str, args.tables))}: {len(names)} subjects\n")
    else:
        chosen = tuple(e for e in ESTIMATORS if not args.estimators or e[0] in args.estimators)
        rows = run_coordinates(names, config, args.ik_noise_scale, args.jobs, estimators=chosen)
        print(f"{args.subjects} subjects, {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    if args.keep:
        args.keep.parent.mkdir(parents=True, exist_ok=True)
        rows.to_csv(args.keep, sep="\t", index=False)
    layered = f" --configfile {' '.join(args.configfile)}" if args.configfile else ""
    print(
        ""
        if args.tables
        else f"python benchmarks/estimators.py --subjects {args.subjects} --first {args.first} --seed {args.seed} "
        f"--ik-noise-scale {args.ik_noise_scale:g}{layered} (coordinate level; trials of "
        f"{config['synthetic']['walking_duration_s']:g} s, {config['trials']['perturbation_repeats']} per onset)\n",
    )
    pooled = estimator_table(rows)
    print(markdown_table(pooled.round(3)))
    print()
    print(markdown_table(estimator_table(rows, by_onset=True).round(3)))
    print()
    print(markdown_table(rmse_ratio(pooled).round(3)))


if __name__ == "__main__":
    main()
