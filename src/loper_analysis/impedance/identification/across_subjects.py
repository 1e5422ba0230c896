"""Impedance across subjects: the summary per joint, onset and parameter (a random-effects mean of the
subjects' estimates with its 95 % interval, the truth's recovery) and the study's published values beside it.

* :func:`impedance_summary` - one row per joint x onset x parameter from the impedance table
  (:mod:`loper_analysis.impedance.identification.impedance`);
* :func:`literature_table` - those rows beside the study's means (:data:`loper_analysis.reference.LITERATURE`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.impedance.identification.group_mean import random_effects_mean
from loper_analysis.reference import LITERATURE

__all__ = ["TRUTH_TOLERANCE", "impedance_summary", "literature_table"]

#: An estimate is within tolerance of the truth when ``|error| <= max(relative * |truth|, absolute)``:
#: parameter -> (relative, absolute in N·m/rad for K, N·m·s/rad for D).
TRUTH_TOLERANCE: dict[str, tuple[float, float]] = {"K": (0.10, 2.0), "D": (0.15, 0.05)}


def impedance_summary(
    table: pd.DataFrame,
    k_tolerance=TRUTH_TOLERANCE["K"],
    d_tolerance=TRUTH_TOLERANCE["D"],
    upper_bounds: tuple[float, float] | None = None,
    lower_bounds: tuple[float, float] = (0.0, 0.0),
) -> pd.DataFrame:
    """Across-subject summary per joint and onset of the fitted rows (``ok`` and ``not_identifiable``).

    ``upper_bounds`` (K in N·m/rad, D in N·m·s/rad; the identification's
    upper bounds): rows whose K or D sits on its upper bound (within
    :data:`~loper_analysis.impedance.identification.AT_BOUND_FRACTION` of the bound)
    carry no estimate and are left out; None keeps every fitted row.
    ``lower_bounds`` (K, D; the identification's lower bounds): the
    random-effects intervals are cut there, as the fits' own intervals are
    (at 0 by default, the physical limit; a negative bound leaves negative
    means and intervals, ``docs/identification.md``).

    Rows that are ``not_identifiable`` because an interval holds 0 and the
    whole plausible range, or is wider than it, stay in: their estimate is still the fit's best
    value, and leaving out exactly the estimates near 0 would push the
    across-subject mean up. ``n_not_identifiable`` counts them, so a mean
    made mostly of uninformative fits shows as such.

    Columns ``joint, onset_ms, n_subjects, n_not_identifiable``, then per parameter its mean, SD,
    min and max over subjects (``K_mean_nm_per_rad`` ...); the random-effects mean with its 95 % interval
    (cut at the lower bound, as the fits' intervals are), which carries each fit's own standard error and the
    between-subject spread
    (:func:`loper_analysis.impedance.identification.group_mean.random_effects_mean`: ``K_group_mean_nm_per_rad``,
    ``K_group_ci95_low_nm_per_rad``, ``K_group_ci95_high_nm_per_rad``, ``K_between_sd_nm_per_rad``);
    ``vaf_pct_mean``; where the truth is known also the mean error, the largest absolute error, the
    fraction of subjects within tolerance (``K_fraction_within_tolerance``:
    ``|error| <= max(rel * |truth|, abs)``), the mean of the subjects' truths (``K_true_mean_nm_per_rad``)
    and whether the random-effects interval holds it (``K_group_truth_in_ci95``) for K and D.
    """
    fitted = table[table["status"].isin(["ok", "not_identifiable"])]
    if upper_bounds is not None:
        from loper_analysis.impedance.identification import AT_BOUND_FRACTION

        on_bound = np.zeros(len(fitted), dtype=bool)
        for p, bound in zip(("K", "D"), upper_bounds, strict=True):
            on_bound |= fitted[parameter_column(p)].to_numpy(float) >= bound * (1.0 - AT_BOUND_FRACTION)
        fitted = fitted[~on_bound]
    rows = []
    for (joint, onset), g in fitted.groupby(["joint", "onset_ms"], sort=False):
        row = {
            "joint": joint,
            "onset_ms": int(onset),
            "n_subjects": g["subject"].nunique(),
            "n_not_identifiable": int((g["status"] == "not_identifiable").sum()),
        }
        for p in ("K", "D"):
            v = g[parameter_column(p)]
            row.update(
                {
                    parameter_column(p, "mean"): v.mean(),
                    parameter_column(p, "sd"): v.std(ddof=1),
                    parameter_column(p, "min"): v.min(),
                    parameter_column(p, "max"): v.max(),
                }
            )
        for p, floor in zip(("K", "D"), lower_bounds, strict=True):
            estimates, errors = (g[parameter_column(p, w)].to_numpy(float) for w in ("", "se"))
            group = random_effects_mean(estimates, errors)
            row.update(
                {
                    parameter_column(p, "group_mean"): group.mean,
                    # cut at the lower bound (0: the parameters' physical limit), as the fits' own intervals are
                    parameter_column(p, "group_ci95_low"): max(group.ci95_low, float(floor))
                    if not np.isnan(group.ci95_low)
                    else group.ci95_low,
                    parameter_column(p, "group_ci95_high"): group.ci95_high,
                    parameter_column(p, "between_sd"): group.between_sd,
                }
            )
        row["vaf_pct_mean"] = g["vaf_pct"].mean()
        known = g[g[parameter_column("K", "true")].notna()]
        if len(known):
            for p, (rel, ab) in (("K", k_tolerance), ("D", d_tolerance)):
                err = known[parameter_column(p, "error")]
                tol = np.maximum(rel * known[parameter_column(p, "true")].abs(), ab)
                true_mean = known[parameter_column(p, "true")].mean()
                low, high = row[parameter_column(p, "group_ci95_low")], row[parameter_column(p, "group_ci95_high")]
                row.update(
                    {
                        parameter_column(p, "error_mean"): err.mean(),
                        parameter_column(p, "max_abs_error"): err.abs().max(),
                        f"{p}_fraction_within_tolerance": float((err.abs() <= tol).mean()),
                        parameter_column(p, "true_mean"): true_mean,
                        f"{p}_group_truth_in_ci95": bool(low <= true_mean <= high) if len(known) == len(g) else None,
                    }
                )
        rows.append(row)
    order = {j: i for i, j in enumerate(JOINTS)}
    out = pd.DataFrame(rows, columns=None if rows else ["joint", "onset_ms", "n_subjects", "n_not_identifiable"])
    if len(out):
        out = out.sort_values(
            ["joint", "onset_ms"],
            key=lambda c: c.map(order) if c.name == "joint" else c,
            kind="stable",
            ignore_index=True,
        )
    return out


def literature_table(summary: pd.DataFrame) -> pd.DataFrame:
    """The literature values (:data:`loper_analysis.reference.LITERATURE`) with our row: the range over onsets of
    the across-subject mean (N·m/rad, N·m·s/rad)."""
    k_low, k_high = parameter_column("K", "low"), parameter_column("K", "high")
    d_low, d_high = parameter_column("D", "low"), parameter_column("D", "high")
    rows = [
        {"source": s, "joint": j, k_low: k[0], k_high: k[1], d_low: d[0], d_high: d[1]} for s, j, k, d in LITERATURE
    ]
    for joint in ("hip", "knee"):
        if "joint" not in summary.columns:  # nothing fitted
            break
        g = summary[summary["joint"] == joint]
        if len(g):
            rows.append(
                {
                    "source": "this pipeline: swing phase, across-subject mean over onsets",
                    "joint": joint,
                    k_low: g[parameter_column("K", "mean")].min(),
                    k_high: g[parameter_column("K", "mean")].max(),
                    d_low: g[parameter_column("D", "mean")].min(),
                    d_high: g[parameter_column("D", "mean")].max(),
                }
            )
    return pd.DataFrame(rows)
