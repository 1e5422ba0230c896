"""Does the planner predict the SD of K and D? Predicted against measured over repeated synthetic experiments.

Usage: nice -n 10 python benchmarks/planner_check.py [--repeats 60] [--onset-ms 50] [--strides 10 40] [--seed 2024]
                                                     [--variability study|gentle]
                                                     [--counterfactual conditional|matched_stride]
                                                     [--pilots-from-repeats] [--shank-force-n 40]

A pilot experiment (one synthetic trial with the device, perturbed at the onset every 3-5 strides, built at
the coordinate level by :func:`loper_analysis.synthetic.coordinate_trials.perturbation_experiment`: no markers, no IK;
the force at the robot's 1000 Hz as the fit takes it; the lab's variability of ``config/config.yaml``
``synthetic`` unless ``--variability`` says otherwise) gives the null pairs, its perturbed pairs and, from its
own fit of all its perturbed strides, the planned impedance; the planner (:mod:`loper_analysis.planning.precision`)
predicts the SD of every K and D for one stride from the perturbed pairs' scatter. Then ``--repeats``
independent experiments (other seeds, same subject) are fitted exactly as the pipeline fits them
(:func:`loper_analysis.impedance.identification.impedance.fit_onset`, null-pair noise model, intervals from the
perturbed pairs'
scatter) with their first N perturbed strides, for each N of ``--strides``; their null pairs come from the
whole trial. The measured SD is the SD of the estimates over the repeats; the prediction for the same repeats
is ``sd_1 * sqrt(mean(1 / n_i))``, n_i the strides each fit kept. Prints the table predicted vs measured
(ratio, and the measured SD's own 95 % range), with the fits' own reported SE, the share of the repeats whose
joint row is ``not_identifiable`` and the share whose 95 % interval holds the truth.

``--counterfactual conditional`` (the workflow's default; without the option the study's matched stride) plans
and fits with the conditional counterfactual instead: the prediction is
:func:`loper_analysis.planning.covariance.conditional_stride_covariance` of the pilot (its cross-validated null
pairs and its perturbed strides' prediction weights), the fits are the pipeline's defaults (averaging term,
intervals from the cross-validated null pairs); as for the matched stride each repeat is its trial cut after
its N-th perturbed stride, so its candidates (the unperturbed strides of the cut trial) grow with N, as the
planner assumes; the prediction for the repeats is the mean of ``sd_of(n_i)^2`` over them. For a count N the
pilot holds at least twice, the workflow's plan and this prediction come from the pilot's stretches of N perturbed
strides (:func:`loper_analysis.planning.covariance.stretch_covariances`; ``predicted_from`` says which, and
``whole_pilot_predicted_sd`` gives the whole pilot's extrapolation beside it). Repeats whose fit
fails or falls back to the matched stride (fewer than ``impedance.min_null_pairs`` candidates) are left
out and listed.

``--pilots-from-repeats``: one pilot is one draw. Every kept repeat also plans exactly as the pilot does (from
its whole trial and its fit of all its perturbed strides, one more prediction per repeat); the table gains
``pilots``, the 5th, 50th and 95th percentiles of their predictions over the measured SD and the share of
them within ±25 % of it (each pilot is also one of the repeats whose SD is measured).

``--shank-force-n F``: the pilot and the repeats are pushed by a second rod just above the ankle too (an F N pulse
with the thigh's, its load cell in the force tables), the planner plans that design
(``PlanSettings.shank_pulse_force_n``) and the fits take both rods.
"""

from __future__ import annotations

import argparse
import logging
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import yaml
from scipy.stats import t as student_t

from loper_analysis.constants import JOINTS, PARAMETERS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.impedance import IdentificationSettings, fit_onset
from loper_analysis.impedance.responses import ResponseSettings, null_pair_windows
from loper_analysis.planning.covariance import conditional_stride_covariance, stretch_covariances, stride_covariance
from loper_analysis.planning.inputs import PLANNED_COUNTERFACTUAL, pilot_onset_series, pilot_perturbed_pairs
from loper_analysis.planning.window import PlanSettings
from loper_analysis.report.markdown import markdown_table
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment
from loper_analysis.synthetic.variability import lab_variability

ROOT = Path(__file__).resolve().parents[1]

#: The true impedance of the synthetic subject per onset (ms): the default study's group values.
TRUTH = {
    50: (55.0, 3.5, 3.0, 0.10, 8.0, 0.3),
    175: (38.0, 2.2, 0.5, 0.04, 8.0, 0.3),
    300: (62.0, 4.2, 2.5, 0.12, 8.0, 0.3),
}
HEIGHT_M, MASS_KG = 1.73, 64.9
ANGLE_NOISE_SD_RAD = 0.001


def estimates(rows: pd.DataFrame) -> np.ndarray:
    """K, D per joint (6,) in the order of PARAMETERS from the three rows of a fit."""
    by_joint = rows.set_index("joint")
    return np.array([by_joint.loc[j, parameter_column(p)] for j in JOINTS for p in ("K", "D")], float)


def truth_in_ci95(rows: pd.DataFrame, truth) -> np.ndarray:
    """Whether each of the six 95 % intervals of one fit's rows holds its truth (order :data:`PARAMETERS`)."""
    r = rows.set_index("joint")
    out = []
    for name, value in zip(PARAMETERS, truth, strict=True):
        p, joint = name.split("_")
        low, high = r.loc[joint, parameter_column(p, "ci95_low")], r.loc[joint, parameter_column(p, "ci95_high")]
        out.append(bool(low <= value <= high))
    return np.array(out)


def reported_sd(rows: pd.DataFrame) -> np.ndarray:
    """The SD (6,) the fit itself reports: the upper half of its 95 % CI (the lower end may be cut at 0) over
    Student's t with the fit's degrees of freedom (``ci_dof``)."""
    by_joint = rows.set_index("joint")
    high = by_joint[[parameter_column(p, "ci95_high") for p in ("K", "D")]].loc[list(JOINTS)].to_numpy(float).ravel()
    return (high - estimates(rows)) / student_t.ppf(0.975, int(rows["ci_dof"].iloc[0]))


def pilot_spread(ratios: np.ndarray) -> dict:
    """Columns for the predictions of many pilots over the measured SD (``ratios`` (n,)): their count, 5th,
    50th and 95th percentiles and the share within ±25 % (NaN without pilots)."""
    if ratios.size == 0:
        return {
            "pilots": 0,
            **{
                c: np.nan
                for c in ("pilots_ratio_p05", "pilots_ratio_median", "pilots_ratio_p95", "pilots_within_25pct")
            },
        }
    p05, p50, p95 = np.percentile(ratios, [5, 50, 95])
    return {
        "pilots": int(ratios.size),
        "pilots_ratio_p05": p05,
        "pilots_ratio_median": p50,
        "pilots_ratio_p95": p95,
        "pilots_within_25pct": float(np.mean(np.abs(ratios - 1.0) <= 0.25)),
    }


def lab(variability: str, seed: int, onset_ms: int, truth) -> dict:
    """Keyword arguments of perturbation_experiment for the lab's variability (config ``synthetic``)."""
    syn = yaml.safe_load((ROOT / "config/config.yaml").read_text())["synthetic"]
    syn = {**syn, "variability": variability or syn["variability"]}
    nested = {onset_ms: {j: {"K": truth[2 * i], "D": truth[2 * i + 1]} for i, j in enumerate(JOINTS)}}
    v, a, m = lab_variability(syn, seed, "P01", nested)
    return {"variability": v, "adaptation": a, "minimal_impedance": m}


def run_check(
    repeats: int,
    onset_ms: int,
    counts: list[int],
    seed: int,
    truth=None,
    n_starts: int = 10,
    verbose: bool = True,
    angle_noise_sd_rad: float = ANGLE_NOISE_SD_RAD,
    variability: str | None = None,
    counterfactual: str = PLANNED_COUNTERFACTUAL,
    pilots_from_repeats: bool = False,
    shank_force_n: float = 0.0,
) -> pd.DataFrame:
    """Predicted and measured SD per parameter and stride count (hip, knee, ankle; K and D).

    With ``pilots_from_repeats`` every kept repeat also plans as the pilot does (from its whole trial and its
    fit of all its perturbed strides), and the rows gain the spread of those predictions over the measured SD
    (:func:`pilot_spread`). ``shank_force_n`` (N): a second rod's pulse at the shank in every experiment and plan.
    """
    truth = TRUTH[onset_ms] if truth is None else truth
    params = segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)
    conditional = counterfactual == "conditional"
    if conditional:  # the pipeline's defaults: averaging term, intervals from the cross-validated null pairs
        ident = IdentificationSettings(n_starts=n_starts, seed=seed)
    else:  # the study's matched strides, intervals from the perturbed pairs' scatter
        ident = IdentificationSettings(n_starts=n_starts, seed=seed, interval_scatter="perturbed_pairs")
    response = ResponseSettings(counterfactual=counterfactual)
    lab_kwargs = lab(variability, seed, onset_ms, truth)

    def experiment(k: int):
        full, cut = perturbation_experiment(
            [seed, k],
            params,
            HEIGHT_M,
            onset_ms,
            truth,
            counts,
            angle_noise_sd_rad=angle_noise_sd_rad,
            shank_force_n=shank_force_n,
            **lab_kwargs,
        )
        return full, cut

    def plan_from(full, fit_rows):
        """The planner's (prediction, null pairs' prediction, {count: prediction from the pilot's stretches})
        from one experiment and its fit of all strides."""
        planned = np.clip(estimates(fit_rows), ident.lower, ident.upper)
        if conditional:
            plan = PlanSettings(shank_pulse_force_n=shank_force_n)
            sc = conditional_stride_covariance(pilot_onset_series([full], onset_ms, response), params, planned, plan)
            by_count = stretch_covariances([full], onset_ms, counts, params, planned, settings=plan, response=response)
            return sc, sc, by_count
        null = null_pair_windows([full], onset_ms, response, source="pilot")
        pairs = pilot_perturbed_pairs([full], onset_ms, response)
        plan = PlanSettings(interval_scatter="perturbed_pairs", shank_pulse_force_n=shank_force_n)
        return (
            stride_covariance(null, params, planned, plan, perturbed_pairs=pairs),
            stride_covariance(null, params, planned, plan),
            {},
        )

    # the pilot: its null pairs, and its fit of all its perturbed strides as the planned impedance
    full, cut = experiment(0)
    pilot_fit = fit_onset([cut[max(counts)]], params, onset_ms, "pilot", None, [full], response, ident)
    planned = np.clip(estimates(pilot_fit.rows), ident.lower, ident.upper)
    sc, sc_null, by_count = plan_from(full, pilot_fit.rows)
    repeat_plans = []  # with pilots_from_repeats: each kept repeat's own plan, as if it had been the pilot
    found = {n: [] for n in counts}
    kept = {n: [] for n in counts}
    reported = {n: [] for n in counts}
    statuses = {n: [] for n in counts}
    inside = {n: [] for n in counts}
    t0 = time.perf_counter()
    skipped = []
    for k in range(1, repeats + 1):
        full, cut = experiment(k)
        try:
            fits = {n: fit_onset([cut[n]], params, onset_ms, f"R{k}", None, [full], response, ident) for n in counts}
        except np.linalg.LinAlgError as exc:  # a fit that raises: the repeat is left out and counted
            skipped.append(f"repeat {k}: {exc}")
            continue
        unlike = [
            f"repeat {k}, {n} strides: {fit.rows['status'].iloc[0]}: {fit.rows['reason'].iloc[0]}"
            for n, fit in fits.items()
            if fit.rows["status"].iloc[0] == "failed"
            or fit.rows["noise_model"].iloc[0] != "null_pairs"
            or "instead of the conditional" in str(fit.rows["reason"].iloc[0])
        ]
        if unlike:  # not fitted, or fitted another way than planned: the repeat is left out and counted
            skipped += unlike
            continue
        if pilots_from_repeats:
            try:
                plan_k = plan_from(full, fits[max(counts)].rows)
                repeat_plans.append((plan_k[0], plan_k[2]))
            except LoperInputError as exc:  # a repeat that cannot be planned from: counted, its fits kept
                skipped.append(f"repeat {k} as a pilot: {exc}")
        for n, fit in fits.items():
            found[n].append(estimates(fit.rows))
            kept[n].append(int(fit.rows["n_strides"].iloc[0]))
            reported[n].append(reported_sd(fit.rows))
            statuses[n].append(fit.rows.set_index("joint").loc[list(JOINTS), "status"].to_numpy())
            inside[n].append(truth_in_ci95(fit.rows, truth))
        if verbose and k % 10 == 0:
            print(f"  {k} repeats, {time.perf_counter() - t0:.0f} s", flush=True)
    rows = []
    for n in counts:
        est = np.array(found[n])
        n_kept = np.array(kept[n], float)
        measured = est.std(axis=0, ddof=1)
        # robust: 1.4826 x the median absolute deviation (the SD for normal estimates; deaf to a few wild fits)
        robust = 1.4826 * np.median(np.abs(est - np.median(est, axis=0)), axis=0)
        whole = np.sqrt(np.mean([sc.sd_of(int(m)) ** 2 for m in n_kept], axis=0))
        predicted = np.sqrt(np.mean([by_count.get(n, sc).sd_of(int(m)) ** 2 for m in n_kept], axis=0))
        predicted_null = np.sqrt(np.mean([sc_null.sd_of(int(m)) ** 2 for m in n_kept], axis=0))
        fits_say = np.sqrt(np.mean(np.array(reported[n]) ** 2, axis=0))
        not_identifiable = np.mean(np.array(statuses[n]) == "not_identifiable", axis=0)  # (3,) per joint
        covered = np.mean(inside[n], axis=0)
        # every repeat as the pilot: its prediction for the same repeats over the measured SD
        pilot_ratios = np.array(
            [
                np.sqrt(np.mean([by.get(n, r).sd_of(int(m)) ** 2 for m in n_kept], axis=0)) / measured
                for r, by in repeat_plans
            ]
        ).reshape(-1, 6)
        # 95 % range of a sample SD over `repeats` normal draws, relative
        rel = 1.96 / np.sqrt(2.0 * (len(est) - 1))
        for i, name in enumerate(PARAMETERS):
            p, joint = name.split("_")
            rows.append(
                {
                    "joint": joint,
                    "parameter": p,
                    "n_strides": n,
                    "mean_n_kept": n_kept.mean(),
                    "truth": truth[i],
                    "planned": planned[i],
                    "mean_estimate": est[:, i].mean(),
                    "predicted_sd": predicted[i],
                    "predicted_from": "stretches" if n in by_count else "whole_pilot",
                    "whole_pilot_predicted_sd": whole[i],
                    "null_pairs_predicted_sd": predicted_null[i],
                    "fits_reported_sd": fits_say[i],
                    "share_not_identifiable": not_identifiable[i // 2],
                    "share_truth_in_ci95": covered[i],
                    "measured_sd": measured[i],
                    "measured_sd_mad": robust[i],
                    "measured_sd_95_low": measured[i] * (1 - rel),
                    "measured_sd_95_high": measured[i] * (1 + rel),
                    "ratio_predicted_to_measured": predicted[i] / measured[i],
                    "repeats": len(est),
                    **pilot_spread(pilot_ratios[:, i]),
                }
            )
    out = pd.DataFrame(rows)
    out.attrs = {
        "n_null_pairs": sc.n_null_pairs,
        "n_perturbed_pairs": sc.n_perturbed_pairs,
        "skipped": skipped,
        "counterfactual": counterfactual,
    }
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=60)
    ap.add_argument("--onset-ms", type=int, default=50, choices=sorted(TRUTH))
    ap.add_argument("--strides", type=int, nargs="+", default=[10, 40])
    ap.add_argument("--seed", type=int, default=2024)
    ap.add_argument("--angle-noise-sd-rad", type=float, default=ANGLE_NOISE_SD_RAD)
    ap.add_argument(
        "--variability",
        choices=("study", "gentle"),
        default=None,
        help="the lab's variability (default: config/config.yaml synthetic.variability)",
    )
    ap.add_argument(
        "--counterfactual",
        choices=("matched_stride", "conditional"),
        default=PLANNED_COUNTERFACTUAL,
        help="plan and fit with this counterfactual (default: the study's matched stride)",
    )
    ap.add_argument(
        "--pilots-from-repeats",
        action="store_true",
        help="every repeat also plans as the pilot: the spread of the predictions over pilots",
    )
    ap.add_argument(
        "--shank-force-n",
        type=float,
        default=0.0,
        help="a second rod's pulse just above the ankle with the thigh's (N; default 0: the thigh rod alone)",
    )
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    logging.disable(logging.WARNING)
    t0 = time.perf_counter()
    table = run_check(
        args.repeats,
        args.onset_ms,
        args.strides,
        args.seed,
        angle_noise_sd_rad=args.angle_noise_sd_rad,
        variability=args.variability,
        counterfactual=args.counterfactual,
        pilots_from_repeats=args.pilots_from_repeats,
        shank_force_n=args.shank_force_n,
    )
    print(
        f"{args.counterfactual}, shank rod {args.shank_force_n:g} N, onset {args.onset_ms} ms, "
        f"angle noise {args.angle_noise_sd_rad:g} rad, "
        f"{args.repeats} repeats, "
        f"pilot null pairs {table.attrs['n_null_pairs']}, perturbed pairs {table.attrs['n_perturbed_pairs']}, "
        f"{time.perf_counter() - t0:.0f} s"
    )
    for line in table.attrs["skipped"]:
        print(f"left out: {line}")
    print(markdown_table(table.round(4)))
    hk = table[table["joint"].isin(["hip", "knee"])]
    worst = hk.loc[(hk["ratio_predicted_to_measured"] - 1).abs().idxmax()]
    print(
        f"hip and knee: ratio predicted/measured {hk['ratio_predicted_to_measured'].min():.3f} .. "
        f"{hk['ratio_predicted_to_measured'].max():.3f} (worst: {worst['joint']} {worst['parameter']} at "
        f"{worst['n_strides']} strides); "
        f"within ±25 %: {bool(((hk['ratio_predicted_to_measured'] - 1).abs() <= 0.25).all())}"
    )
    if args.pilots_from_repeats:
        cells = hk[["joint", "parameter", "n_strides", "pilots_ratio_p05", "pilots_ratio_median", "pilots_ratio_p95"]]
        print(
            f"every repeat as the pilot ({int(hk['pilots'].min())} pilots): hip and knee predictions within ±25 % "
            f"of the measured SD in {hk['pilots_within_25pct'].mean():.0%} of pilot x cell; per cell:"
        )
        print(markdown_table(cells.round(2)))


if __name__ == "__main__":
    main()
