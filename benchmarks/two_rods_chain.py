"""Truth recovery through the whole chain, thigh rod alone against both rods, and the planner against the fits.

Usage: python benchmarks/two_rods_chain.py RUN [RUN ...] [--labels A B ...]

Each RUN is the folder of a finished workflow run with synthetic subjects (``results/impedance/impedance.tsv``
with the truth columns and ``results/planning/plan.tsv``), e.g. ``snakemake -j2 --configfile config/paper.yaml``
(thigh rod alone) and ``snakemake -j2 --configfile config/paper.yaml config/two_rods.yaml`` (both rods) in two
copies of the project. Prints, per run, joint and parameter (rows ``ok`` or ``not_identifiable``):

* the estimates within the study's tolerance (K 10 % or 2 N·m/rad, D 15 % or 0.05 N·m·s/rad, the larger) and
  the 95 % intervals holding the truth, each with its binomial (Clopper-Pearson) 95 % interval;
* the precision reached: the median standard error the fits report (``*_se_*``), the RMS error against the
  truth and the median 95 % half-width, at the run's perturbed strides per fit (median ``n_strides``);
* the strides a fit would need for a 95 % half-width of the study's tolerance at that joint (the fits'
  half-widths scaled by 1/sqrt(n): median over fits of n (half-width / tolerance)^2);
* the planner's prediction for the same fits (``plan.tsv`` of the pilot: its SD at each fit's own stride count,
  as sd_N sqrt(N / n), RMS over the fits of each onset) over the fits' reported standard errors (RMS), per onset.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd
from scipy.stats import beta

from loper_analysis.constants import JOINTS
from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE
from loper_analysis.report.markdown import markdown_table
from loper_analysis.stages import study_paths

UNITS = {"K": "nm_per_rad", "D": "nms_per_rad"}
PATHS = study_paths()


def clopper_pearson(k: int, n: int) -> tuple[float, float]:
    """The exact binomial 95 % interval of a share k / n."""
    lo = beta.ppf(0.025, k, n - k + 1) if k > 0 else 0.0
    hi = beta.ppf(0.975, k + 1, n - k) if k < n else 1.0
    return float(lo), float(hi)


def share(k: int, n: int) -> str:
    lo, hi = clopper_pearson(k, n)
    return f"{k} / {n} ({100 * k / n:.0f} %; {100 * lo:.0f}–{100 * hi:.0f})"


def tolerance(p: str, truth: np.ndarray) -> np.ndarray:
    """The study's tolerance of ``p`` at the true values ``truth``: the larger of the relative and the absolute."""
    rel, absolute = TRUTH_TOLERANCE[p]
    return np.maximum(rel * np.abs(truth), absolute)


def recovery(fits: pd.DataFrame) -> pd.DataFrame:
    """The per joint and parameter rows described in the module's docstring (without the planner's column)."""
    rows = []
    for joint in JOINTS:
        g = fits[fits["joint"] == joint]
        for p, unit in UNITS.items():
            est, truth = g[f"{p}_{unit}"].to_numpy(float), g[f"{p}_true_{unit}"].to_numpy(float)
            low, high = g[f"{p}_ci95_low_{unit}"].to_numpy(float), g[f"{p}_ci95_high_{unit}"].to_numpy(float)
            tol = tolerance(p, truth)
            n, half = g["n_strides"].to_numpy(float), (high - low) / 2
            rows.append(
                {
                    "joint": joint,
                    "parameter": p,
                    "within_tolerance": share(int(np.sum(np.abs(est - truth) <= tol)), len(g)),
                    "ci95_holds_truth": share(int(np.sum((low <= truth) & (truth <= high))), len(g)),
                    "median_strides": float(np.median(n)),
                    "median_se": float(np.median(g[f"{p}_se_{unit}"])),
                    "rms_error": float(np.sqrt(np.mean((est - truth) ** 2))),
                    "median_ci95_half_width": float(np.median(half)),
                    "strides_for_tolerance": float(np.median(n * (half / tol) ** 2)),
                }
            )
    return pd.DataFrame(rows)


def planner_over_fits(fits: pd.DataFrame, plan: pd.DataFrame) -> pd.DataFrame:
    """Per onset, joint and parameter: the pilot's predicted SD at each fit's stride count (RMS over the onset's
    fits) over the fits' reported standard errors (RMS), and the ratio."""
    rows = []
    for (onset, joint), g in fits.groupby(["onset_ms", "joint"]):
        for p, unit in UNITS.items():
            planned = plan[(plan["onset_ms"] == onset) & (plan["joint"] == joint) & (plan["parameter"] == p)]
            if planned.empty:
                continue
            ref = planned.iloc[-1]  # the largest stride count planned: sd_1 = sd_N sqrt(N)
            sd_1 = float(ref["predicted_sd"]) * np.sqrt(float(ref["n_strides"]))
            predicted = np.sqrt(np.mean(sd_1**2 / g["n_strides"].to_numpy(float)))
            se = g[f"{p}_se_{unit}"].to_numpy(float)
            reported = np.sqrt(np.mean(se[np.isfinite(se)] ** 2)) if np.isfinite(se).any() else np.nan
            rows.append(
                {
                    "onset_ms": int(onset),
                    "joint": joint,
                    "parameter": p,
                    "fits": len(g),
                    "planned_sd": predicted,
                    "fits_reported_se": reported,
                    "ratio": predicted / reported,
                    "within_25pct": bool(abs(predicted / reported - 1) <= 0.25),
                }
            )
    return pd.DataFrame(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("runs", nargs="+", type=Path)
    ap.add_argument("--labels", nargs="+")
    args = ap.parse_args()
    labels = args.labels or [str(r) for r in args.runs]
    for label, run in zip(labels, args.runs, strict=True):
        fits = pd.read_csv(run / PATHS.impedance.table, sep="\t")
        fits = fits[fits["status"].isin(["ok", "not_identifiable"])]
        print(f"## {label}: {len(fits)} joint fits of {fits['subject'].nunique()} subjects\n")
        print(markdown_table(recovery(fits).round(4)))
        plan_path = run / PATHS.planning.plan
        if plan_path.is_file():
            table = planner_over_fits(fits, pd.read_csv(plan_path, sep="\t"))
            within = int(table["within_25pct"].sum())
            print(f"\nplanner over the fits' reported SE: {within} of {len(table)} within ±25 %\n")
            print(markdown_table(table.round(4)))
        print()


if __name__ == "__main__":
    main()
