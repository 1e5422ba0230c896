"""The headline numbers of a run, as tables: impedance with confidence intervals, truth recovery and verdicts.

Pure functions from the result tables (pandas frames, as the file step
:func:`loper_analysis.stages.report.step.front_page` reads them) to the tables the
front page (:mod:`loper_analysis.report.front_page`) shows:

* :func:`impedance_summary_ci` - the across-subject summary with the 95 %
  confidence interval of each mean (Student's t, ``n_subjects - 1`` degrees
  of freedom);
* :func:`truth_recovery` - estimated against true K and D of the synthetic
  subjects, per joint; :func:`ci_coverage_p` - whether the fits' 95 %
  intervals hold the truth as often as they should;
* :func:`transparency_verdict`, :func:`device_comparison`,
  :func:`validation_verdict` - the device's transparency, its force
  controller against the study, the validation study's extremes.

K in N·m/rad, D in N·m·s/rad, angles in rad.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pandas as pd

from loper_analysis.checks import integer, number, require_columns, where
from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE
from loper_analysis.reference import STUDY_DEVICE

__all__ = [
    "FITTED_STATUSES",
    "PARAMETER_KINDS",
    "COVERAGE_TARGET",
    "WITHIN_TOLERANCE_TARGET",
    "impedance_summary_ci",
    "truth_recovery",
    "ci_coverage_p",
    "transparency_verdict",
    "device_comparison",
    "validation_verdict",
]

#: Fit statuses that carry an estimate (``failed`` and ``missing`` rows do not).
FITTED_STATUSES: tuple[str, ...] = ("ok", "not_identifiable")
#: Parameter kinds of the headline tables, in their column order: stiffness K (N·m/rad), damping D (N·m·s/rad).
PARAMETER_KINDS: tuple[str, ...] = ("K", "D")
#: Share of the fits' 95 % intervals that should hold the truth: calibrated intervals hold it in about 95 %; fewer
#: than 90 % is too narrow, more than 98 % too wide to be informative.
COVERAGE_TARGET: tuple[float, float] = (0.90, 0.98)
#: Share of the fits whose K (and D) should lie within tolerance of the truth
#: (:data:`loper_analysis.impedance.identification.across_subjects.TRUTH_TOLERANCE`).
WITHIN_TOLERANCE_TARGET: float = 0.90


def _rows_or_empty(table, columns: Sequence[str], source: str, what: str) -> pd.DataFrame:
    """The table when it has rows (checked for ``columns``), else an empty frame with those columns."""
    if isinstance(table, pd.DataFrame) and len(table) == 0:
        return pd.DataFrame(columns=list(columns))
    return require_columns(table, columns, source, what)


def _numbers(table: pd.DataFrame, column: str, source: str) -> np.ndarray:
    """A numeric column as floats; a cell that is no finite number names its row, column and value."""
    return np.array(
        [number(f"column {column!r}, row {i}", value, source) for i, value in enumerate(table[column].to_numpy())],
        dtype=float,
    )


def impedance_summary_ci(summary: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """The across-subject summary's random-effects means with their 95 % intervals, per joint and onset.

    Parameters
    ----------
    summary : pandas.DataFrame
        ``results/impedance/summary.tsv``: ``joint, onset_ms, n_subjects, n_not_identifiable``,
        ``K_group_mean_nm_per_rad``, ``K_group_ci95_low_nm_per_rad``, ``K_group_ci95_high_nm_per_rad``
        (N·m/rad), the same for D (N·m·s/rad;
        :func:`loper_analysis.impedance.identification.group_mean.random_effects_mean`:
        each fit weighted by its own standard error and the between-subject spread) and ``vaf_pct_mean`` (%).
        No rows: nothing was fitted.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per summary row: ``joint, onset_ms, n_subjects, n_not_identifiable``, per parameter the mean
        and the bounds of its 95 % interval (``K_mean_nm_per_rad``, ``K_ci95_low_nm_per_rad`` ...; NaN bounds
        for fewer than two subjects with information), and ``vaf_pct_mean``.

    Raises
    ------
    LoperInputError
        A column missing, a count that is not an integer >= 1 (or a not-identifiable count above it), a mean
        that is no finite number, or an interval that does not hold its mean.
    """
    needed = [
        "joint",
        "onset_ms",
        "n_subjects",
        "n_not_identifiable",
        "vaf_pct_mean",
        *(parameter_column(p, w) for p in PARAMETER_KINDS for w in ("group_mean", "group_ci95_low", "group_ci95_high")),
    ]
    out_columns = [
        "joint",
        "onset_ms",
        "n_subjects",
        "n_not_identifiable",
        *(parameter_column(p, w) for p in PARAMETER_KINDS for w in ("mean", "ci95_low", "ci95_high")),
        "vaf_pct_mean",
    ]
    table = _rows_or_empty(summary, needed, source, "impedance summary")
    rows = []
    for i, r in enumerate(table.to_dict("records")):
        at = f"{where(source)}row {i} ({r['joint']} {r['onset_ms']} ms)"
        n = integer("n_subjects", r["n_subjects"], at, minimum=1)
        n_ni = integer("n_not_identifiable", r["n_not_identifiable"], at, minimum=0)
        if n_ni > n:
            raise LoperInputError(f"{at}: n_not_identifiable must be <= n_subjects = {n}, got {n_ni}")
        row = {
            "joint": r["joint"],
            "onset_ms": integer("onset_ms", r["onset_ms"], at),
            "n_subjects": n,
            "n_not_identifiable": n_ni,
        }
        for p in PARAMETER_KINDS:
            mean = number(parameter_column(p, "group_mean"), r[parameter_column(p, "group_mean")], at)
            low, high = (float(r[parameter_column(p, w)]) for w in ("group_ci95_low", "group_ci95_high"))
            if not (math.isnan(low) and math.isnan(high)) and not low <= mean <= high:
                raise LoperInputError(
                    f"{at}: the interval [{low}, {high}] of {parameter_column(p, 'group_mean')} = {mean} must hold it"
                )
            row.update(
                {
                    parameter_column(p, "mean"): mean,
                    parameter_column(p, "ci95_low"): low,
                    parameter_column(p, "ci95_high"): high,
                }
            )
        row["vaf_pct_mean"] = number("vaf_pct_mean", r["vaf_pct_mean"], at)
        rows.append(row)
    return pd.DataFrame(rows, columns=out_columns)


def truth_recovery(impedance: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """Estimated against true K and D of the subjects with a known truth (synthetic), per joint.

    Parameters
    ----------
    impedance : pandas.DataFrame
        ``results/impedance/impedance.tsv``
        (:data:`loper_analysis.impedance.identification.impedance.IMPEDANCE_COLUMNS`):
        per subject, onset and joint the estimate, its 95 % CI, the truth and
        the error (estimate - truth; K in N·m/rad, D in N·m·s/rad), and ``status``.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per joint (:data:`~loper_analysis.constants.JOINTS` order)
        with a known truth: ``joint``, ``n_subjects``, ``n_fits`` (rows with a
        status of :data:`FITTED_STATUSES`), ``n_failed`` (the other rows), and
        per parameter over the fits: ``K_error_mean_nm_per_rad`` (bias),
        ``K_error_median_abs_nm_per_rad``, ``K_error_median_abs_pct`` (median
        of ``|error| / |truth|``, %; truths of 0 left out),
        ``K_n_within_tolerance`` (:data:`loper_analysis.impedance.identification.across_subjects.TRUTH_TOLERANCE`,
        the rule of the
        across-subject summary) and
        ``K_n_truth_in_ci95`` (the truth inside the fit's 95 % CI, bounds
        included); the same for D. No truth known: no rows.

    Raises
    ------
    LoperInputError
        A column missing, or a fitted row whose estimate, CI bound or error
        is no finite number (naming the row and the column).
    """
    needed = [
        "subject",
        "onset_ms",
        "joint",
        "status",
        *(parameter_column(p, w) for p in PARAMETER_KINDS for w in ("", "ci95_low", "ci95_high", "true", "error")),
    ]
    counts = ["n_fits", "n_failed"]
    per_p = [(p, w) for p in PARAMETER_KINDS for w in ("error_mean", "error_median_abs")]
    columns = [
        "joint",
        "n_subjects",
        *counts,
        *(parameter_column(p, w) for p, w in per_p),
        *(
            f"{p}_{w}"
            for p in PARAMETER_KINDS
            for w in ("error_median_abs_pct", "n_within_tolerance", "n_truth_in_ci95")
        ),
    ]
    table = _rows_or_empty(impedance, needed, source, "impedance table")
    known = table[pd.to_numeric(table[parameter_column("K", "true")], errors="coerce").notna()].reset_index(drop=True)
    fitted = known[known["status"].isin(FITTED_STATUSES)].reset_index(drop=True)
    values = {}
    for p in PARAMETER_KINDS:
        for w in ("", "ci95_low", "ci95_high", "true", "error"):
            col = parameter_column(p, w)
            values[col] = _numbers(fitted, col, f"{where(source)}fitted rows")
    rows = []
    for joint in [j for j in JOINTS if j in set(known["joint"])] + sorted(set(known["joint"]) - set(JOINTS)):
        own = (fitted["joint"] == joint).to_numpy()
        row = {
            "joint": joint,
            "n_subjects": int(known.loc[known["joint"] == joint, "subject"].nunique()),
            "n_fits": int(own.sum()),
            "n_failed": int((known["joint"] == joint).sum() - own.sum()),
        }
        for p in PARAMETER_KINDS:
            err = values[parameter_column(p, "error")][own]
            true = values[parameter_column(p, "true")][own]
            rel, ab = TRUTH_TOLERANCE[p]
            low, high = values[parameter_column(p, "ci95_low")][own], values[parameter_column(p, "ci95_high")][own]
            nonzero = true != 0
            rel_err = np.abs(err[nonzero]) / np.abs(true[nonzero]) * 100.0
            row.update(
                {
                    parameter_column(p, "error_mean"): float(err.mean()) if err.size else math.nan,
                    parameter_column(p, "error_median_abs"): float(np.median(np.abs(err))) if err.size else math.nan,
                    f"{p}_error_median_abs_pct": float(np.median(rel_err)) if rel_err.size else math.nan,
                    f"{p}_n_within_tolerance": int((np.abs(err) <= np.maximum(rel * np.abs(true), ab)).sum()),
                    f"{p}_n_truth_in_ci95": int(((true >= low) & (true <= high)).sum()),
                }
            )
        rows.append(row)
    return pd.DataFrame(rows, columns=columns)


def ci_coverage_p(n_inside: int, n_total: int, level: float = 0.95) -> float:
    """One-sided binomial p-value of ``n_inside`` or fewer of ``n_total`` intervals holding the truth.

    With nominal coverage ``level``, a small p (below 0.05) says the
    intervals are too narrow. NaN for ``n_total = 0``.
    """
    from scipy.stats import binom

    n_total = integer("n_total", n_total, minimum=0)
    n_inside = integer("n_inside", n_inside, minimum=0)
    if n_inside > n_total:
        raise LoperInputError(f"n_inside must be <= n_total = {n_total}, got {n_inside}")
    return math.nan if n_total == 0 else float(binom.cdf(n_inside, n_total, level))


def _bool_or_none(value, column: str, at: str):
    """True, False or None (no verdict: a blank cell) from a table cell."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return None
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if value in ("True", "true", 1, 1.0):
        return True
    if value in ("False", "false", 0, 0.0):
        return False
    raise LoperInputError(f"{at}: column {column!r} must be True, False or blank, got {value!r}")


def transparency_verdict(rmsd: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """The group rows of the transparency table with, per phase and joint, how many subjects were transparent.

    Parameters
    ----------
    rmsd : pandas.DataFrame
        ``results/transparency/rmsd.tsv``: ``subject`` (``all`` for the
        group), ``phase, joint, rmsd_rad, isv_ave_rad, transparent``
        (RMSD < ISV_ave, blank without strides), ``study_rmsd_rad``,
        ``study_isv_ave_rad``.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per group row: ``phase, joint, rmsd_rad, isv_ave_rad,
        transparent`` (True, False or None), ``study_rmsd_rad,
        study_isv_ave_rad``, ``n_subjects`` (subjects with a verdict) and
        ``n_subjects_transparent``.
    """
    carried = ["phase", "joint", "rmsd_rad", "isv_ave_rad", "transparent", "study_rmsd_rad", "study_isv_ave_rad"]
    columns = [*carried, "n_subjects", "n_subjects_transparent"]
    table = _rows_or_empty(rmsd, ["subject", *carried], source, "transparency table")
    verdicts = [
        _bool_or_none(v, "transparent", f"{where(source)}row {i}")
        for i, v in enumerate(table["transparent"].to_numpy())
    ]
    table = table.assign(transparent=verdicts, subject=table["subject"].astype(str))
    rows = []
    for i, r in table[table["subject"] == "all"].iterrows():
        at = f"{where(source)}row {i} (all {r['phase']} {r['joint']})"
        subjects = table[(table["subject"] != "all") & (table["phase"] == r["phase"]) & (table["joint"] == r["joint"])][
            "transparent"
        ]
        judged = [v for v in subjects if v is not None]
        rows.append(
            {
                "phase": r["phase"],
                "joint": r["joint"],
                **{c: (math.nan if pd.isna(r[c]) else number(c, r[c], at)) for c in ("rmsd_rad", "isv_ave_rad")},
                "transparent": r["transparent"],
                **{
                    c: (math.nan if pd.isna(r[c]) else number(c, r[c], at))
                    for c in ("study_rmsd_rad", "study_isv_ave_rad")
                },
                "n_subjects": len(judged),
                "n_subjects_transparent": int(sum(judged)),
            }
        )
    return pd.DataFrame(rows, columns=columns)


def device_comparison(summary: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """The device figures beside the study's (:data:`loper_analysis.reference.STUDY_DEVICE`).

    Parameters
    ----------
    summary : pandas.DataFrame
        ``results/device/summary.tsv``: ``metric, value`` (and more),
        holding every metric of the study.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per study metric (its order): ``metric, value, study_value,
        unit, difference_pct`` (``(value / study_value - 1) · 100``).
    """
    table = require_columns(summary, ["metric", "value"], source, "device summary")
    by_metric = dict(zip(table["metric"].astype(str), table["value"]))
    rows = []
    for metric, (study, unit) in STUDY_DEVICE.items():
        if metric not in by_metric:
            raise LoperInputError(f"{where(source)}device summary: metric {metric!r} missing (has {sorted(by_metric)})")
        value = number(f"value of metric {metric!r}", by_metric[metric], source)
        rows.append(
            {
                "metric": metric,
                "value": value,
                "study_value": study,
                "unit": unit,
                "difference_pct": (value / study - 1.0) * 100.0,
            }
        )
    return pd.DataFrame(rows, columns=["metric", "value", "study_value", "unit", "difference_pct"])


def validation_verdict(summary: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """The validation study without noise: per parameter kind, the error range over joints against the study's.

    Parameters
    ----------
    summary : pandas.DataFrame
        ``results/validation/summary.tsv``: ``condition, parameter`` (``K_hip``
        ...), ``min_error, max_error, n``, ``study_min_error, study_max_error``.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        Rows K and D (condition ``no_noise``): ``parameter, n_combinations``,
        ``min_error, max_error, study_min_error, study_max_error`` (N·m/rad
        for K, N·m·s/rad for D) and ``within_study`` (the whole range inside
        the study's).
    """
    needed = ["condition", "parameter", "min_error", "max_error", "n", "study_min_error", "study_max_error"]
    table = _rows_or_empty(summary, needed, source, "validation summary")
    clean = table[table["condition"] == "no_noise"].reset_index(drop=True)
    rows = []
    for p in PARAMETER_KINDS:
        g = clean[clean["parameter"].astype(str).str.startswith(f"{p}_")]
        if not len(g):
            continue
        at = f"{where(source)}no_noise {p} rows"
        lo, hi = _numbers(g, "min_error", at), _numbers(g, "max_error", at)
        s_lo, s_hi = _numbers(g, "study_min_error", at), _numbers(g, "study_max_error", at)
        rows.append(
            {
                "parameter": p,
                "n_combinations": integer("n", int(_numbers(g, "n", at).min()), at),
                "min_error": float(lo.min()),
                "max_error": float(hi.max()),
                "study_min_error": float(s_lo.min()),
                "study_max_error": float(s_hi.max()),
                "within_study": bool(lo.min() >= s_lo.min() and hi.max() <= s_hi.max()),
            }
        )
    return pd.DataFrame(
        rows,
        columns=[
            "parameter",
            "n_combinations",
            "min_error",
            "max_error",
            "study_min_error",
            "study_max_error",
            "within_study",
        ],
    )
