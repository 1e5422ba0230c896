"""Where does the bias of the impedance fits come from? The synthetic lab with one part at a time left out.

Usage: python benchmarks/bias_sources.py [--subjects N] [--jobs J] [--seed S] [--variants NAME ...]
                                         [--ik-noise-scale X] [--keep DIR] [--configfile FILE ...] [--study-fit]

N synthetic subjects of the default design (``config/config.yaml``: 2 trials of 45 s per onset; the study's
design with ``--configfile config/paper.yaml``: 4-minute trials), fitted at
the coordinate level as ``benchmarks/ci_coverage.py --mode coordinates`` fits them (the workflow's
``fit_onset`` on the simulated coordinates with IK-like noise), once with the study-level lab as it is
and once with each candidate departure from what the identification model assumes left out:

* ``no_adaptation``: the subject's gait adaptation to the device;
* ``no_minimal_impedance``: the leg's answer to the minimal-impedance force on every swing (only the
  pulses act, as the gentle lab has it);
* ``no_variability``: the study-level stride-to-stride variability (the gentle lab's instead);
* ``gentle``: all three left out;
* ``exact_counterfactual``: the counterfactual's error left out: every perturbation trial is simulated a
  second time without its pulses (same walking, same noise), and each perturbed stride is fitted against its
  own twin (the study's matching finds it at distance 0), so what remains is the model's;
* ``exact_counterfactual_no_variability``: that, with the gentle lab's variability.

``--study-fit``: the study's fit of the mean response (``impedance.averaging_correction: false``) instead of
the default with the averaging term.

Prints, per variant, onset, joint and parameter, over the fitted rows (``ok`` or ``not_identifiable``):
the mean error (estimate - truth) with its standard error over subjects, the error SD, their ratio
(mean / SD: a bias beyond a quarter of the scatter shows here), the fits within tolerance and the
intervals that hold the truth. Hip and knee only (the ankle is not identifiable in this design).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

sys.path.insert(0, str(Path(__file__).resolve().parent))

from ci_coverage import run_coordinates, study_lab_config  # noqa: E402

from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE  # noqa: E402
from loper_analysis.report.markdown import markdown_table  # noqa: E402

#: Variant -> lab parts left out (:data:`ci_coverage.LAB_PARTS`).
VARIANTS: dict[str, tuple[str, ...]] = {
    "study_lab": (),
    "no_adaptation": ("adaptation",),
    "no_minimal_impedance": ("minimal_impedance",),
    "no_variability": ("variability",),
    "gentle": ("adaptation", "minimal_impedance", "variability"),
    "exact_counterfactual": ("counterfactual",),
    "exact_counterfactual_no_variability": ("counterfactual", "variability"),
}
UNITS = {"K": "nm_per_rad", "D": "nms_per_rad"}


def bias_table(rows: pd.DataFrame, variant: str) -> pd.DataFrame:
    """Per onset, joint (hip, knee) and parameter: the error's mean, its standard error, SD, mean / SD, the fits
    within tolerance and the intervals holding the truth."""
    fitted = rows[rows["status"].isin(["ok", "not_identifiable"]) & rows["joint"].isin(["hip", "knee"])]
    out = []
    for (onset, joint), g in fitted.groupby(["onset_ms", "joint"], sort=True):
        for p, unit in UNITS.items():
            err = g[f"{p}_error_{unit}"].to_numpy(float)
            true = g[f"{p}_true_{unit}"].to_numpy(float)
            rel, ab = TRUTH_TOLERANCE[p]
            low, high = g[f"{p}_ci95_low_{unit}"].to_numpy(float), g[f"{p}_ci95_high_{unit}"].to_numpy(float)
            sd = float(np.std(err, ddof=1)) if err.size > 1 else np.nan
            out.append(
                {
                    "variant": variant,
                    "onset_ms": int(onset),
                    "parameter": f"{p}_{joint}",
                    "fits": err.size,
                    "mean_error": float(np.mean(err)),
                    "se_of_mean": sd / np.sqrt(err.size),
                    "sd_error": sd,
                    "mean_over_sd": float(np.mean(err)) / sd if sd > 0 else np.nan,
                    "within_tolerance": int(np.sum(np.abs(err) <= np.maximum(rel * np.abs(true), ab))),
                    "truth_in_ci95": int(np.sum((true >= low) & (true <= high))),
                }
            )
    return pd.DataFrame(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subjects", type=int, default=24)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--variants", nargs="+", choices=sorted(VARIANTS), default=list(VARIANTS))
    ap.add_argument("--ik-noise-scale", type=float, default=1.0, help="IK-like noise, times the chain's (0: none)")
    ap.add_argument("--keep", type=Path, help="write every variant's impedance rows here (TSV, one per variant)")
    ap.add_argument("--configfile", nargs="+", default=[], help="config files layered over config/config.yaml")
    ap.add_argument("--study-fit", action="store_true", help="impedance.averaging_correction: false")
    args = ap.parse_args()
    config = study_lab_config(args.configfile, args.seed)
    if args.study_fit:
        config["impedance"]["averaging_correction"] = False
    names = [f"C{k:03d}" for k in range(1, args.subjects + 1)]
    tables = []
    for variant in args.variants:
        t0 = time.perf_counter()
        rows = run_coordinates(names, config, args.ik_noise_scale, args.jobs, VARIANTS[variant])
        if args.keep:
            args.keep.mkdir(parents=True, exist_ok=True)
            rows.to_csv(args.keep / f"{variant}.tsv", sep="\t", index=False)
        tables.append(bias_table(rows, variant))
        print(f"{variant}: {args.subjects} subjects, {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    layered = f" --configfile {' '.join(args.configfile)}" if args.configfile else ""
    print(
        f"python benchmarks/bias_sources.py --subjects {args.subjects} --seed {args.seed} "
        f"--ik-noise-scale {args.ik_noise_scale:g}{layered}{' --study-fit' if args.study_fit else ''} "
        f"--variants {' '.join(args.variants)} "
        f"(coordinate level; trials of "
        f"{config['synthetic']['walking_duration_s']:g} s, {config['trials']['perturbation_repeats']} per onset)\n"
    )
    print(markdown_table(pd.concat(tables, ignore_index=True).round(3)))


if __name__ == "__main__":
    main()
