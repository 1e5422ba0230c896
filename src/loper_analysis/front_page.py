"""The front page of the Snakemake report: what was run, the headline numbers and the main figure, as HTML.

Pure functions from the result tables (pandas frames, as the file step
:func:`loper_analysis.steps.report.front_page` reads them) to one HTML
fragment, which ``workflow/report/workflow.rst`` pulls into the report's
"Workflow" panel above the methods text:

* :func:`impedance_summary_ci` - the across-subject summary with the 95 %
  confidence interval of each mean (Student's t, ``n_subjects - 1`` degrees
  of freedom);
* :func:`truth_recovery` - estimated against true K and D of the synthetic
  subjects, per joint;
* :func:`transparency_verdict`, :func:`device_comparison`,
  :func:`validation_verdict` - the device's transparency, its force
  controller against the study, the validation study's extremes;
* :func:`front_page_html` - the fragment. Its tables carry the ids
  ``lf-impedance-summary``, ``lf-truth-recovery``, ``lf-transparency``,
  ``lf-device`` and ``lf-run``, the figure ``lf-figure``.

Every number the fragment shows sits in a ``<span>`` whose ``data-q`` names
its table, row and column (``table|row|column``) and whose ``data-v`` holds
the value at full precision (``repr``), so the page can be checked against
the tables. The fragment holds no time, host or path: the same tables,
settings, versions and figure give the same bytes. K in N·m/rad, D in
N·m·s/rad, angles in rad.
"""

from __future__ import annotations

import base64
import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .checks import integer, number, require_columns, where
from .constants import JOINTS, PARAMETER_UNITS, parameter_column
from .errors import LoperInputError
from .impedance import TRUTH_TOLERANCE
from .reference import STUDY_DEVICE, STUDY_SWING_IMPEDANCE

__all__ = [
    "FITTED_STATUSES",
    "SOFTWARE",
    "RunSettings",
    "impedance_summary_ci",
    "truth_recovery",
    "ci_coverage_p",
    "transparency_verdict",
    "device_comparison",
    "validation_verdict",
    "front_page_html",
]

#: Fit statuses that carry an estimate (``failed`` and ``missing`` rows do not).
FITTED_STATUSES: tuple[str, ...] = ("ok", "not_identifiable")
#: Software the front page lists: label -> distribution name (Python itself is listed first).
SOFTWARE: dict[str, str] = {
    "loper_analysis": "loper-analysis",
    "OpenSim": "opensim",
    "ezc3d": "ezc3d",
    "NumPy": "numpy",
    "SciPy": "scipy",
    "pandas": "pandas",
    "Snakemake": "snakemake",
}

_PARAMETERS = ("K", "D")
_UNIT = {p: PARAMETER_UNITS[f"{p}_hip"] for p in _PARAMETERS}
_MINUS = "\u2212"


# --------------------------------------------------------------------------------------------------- tables


def _rows_or_empty(table, columns: Sequence[str], source: str, what: str) -> pd.DataFrame:
    """The table when it has rows (checked for ``columns``), else an empty frame with those columns."""
    if isinstance(table, pd.DataFrame) and len(table) == 0:
        return pd.DataFrame(columns=list(columns))
    return require_columns(table, columns, source, what)


def _numbers(table: pd.DataFrame, column: str, source: str) -> np.ndarray:
    """A numeric column as floats; a cell that is no finite number names its row, column and value."""
    return np.array([number(f"column {column!r}, row {i}", value, source)
                     for i, value in enumerate(table[column].to_numpy())], dtype=float)


def impedance_summary_ci(summary: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """The across-subject summary with the 95 % confidence interval of each mean.

    Parameters
    ----------
    summary : pandas.DataFrame
        ``results/tables/impedance_summary.tsv``: ``joint, onset_ms,
        n_subjects, n_not_identifiable``, ``K_mean_nm_per_rad``,
        ``K_sd_nm_per_rad`` (N·m/rad), ``D_mean_nms_per_rad``,
        ``D_sd_nms_per_rad`` (N·m·s/rad) and ``vaf_pct_mean`` (%). No rows:
        nothing was fitted.
    source : str
        Where the table came from, for error messages.

    Returns
    -------
    pandas.DataFrame
        One row per summary row: ``joint, onset_ms, n_subjects,
        n_not_identifiable``, per parameter its mean and the bounds of the
        95 % CI of the mean, ``mean ± t(0.975, n - 1) · sd / sqrt(n)``
        (``K_ci95_low_nm_per_rad`` ...; NaN for one subject), and
        ``vaf_pct_mean``.

    Raises
    ------
    LoperInputError
        A column missing, a count that is not an integer >= 1 (or a
        not-identifiable count above it), a mean that is no finite number,
        or no SD where two or more subjects were averaged.
    """
    from scipy.stats import t as student_t

    needed = ["joint", "onset_ms", "n_subjects", "n_not_identifiable", "vaf_pct_mean",
              *(parameter_column(p, w) for p in _PARAMETERS for w in ("mean", "sd"))]
    out_columns = ["joint", "onset_ms", "n_subjects", "n_not_identifiable",
                   *(parameter_column(p, w) for p in _PARAMETERS for w in ("mean", "ci95_low", "ci95_high")),
                   "vaf_pct_mean"]
    table = _rows_or_empty(summary, needed, source, "impedance summary")
    rows = []
    for i, r in enumerate(table.to_dict("records")):
        at = f"{where(source)}row {i} ({r['joint']} {r['onset_ms']} ms)"
        n = integer("n_subjects", r["n_subjects"], at, minimum=1)
        n_ni = integer("n_not_identifiable", r["n_not_identifiable"], at, minimum=0)
        if n_ni > n:
            raise LoperInputError(f"{at}: n_not_identifiable must be <= n_subjects = {n}, got {n_ni}")
        row = {"joint": r["joint"], "onset_ms": integer("onset_ms", r["onset_ms"], at), "n_subjects": n,
               "n_not_identifiable": n_ni}
        for p in _PARAMETERS:
            mean = number(parameter_column(p, "mean"), r[parameter_column(p, "mean")], at)
            if n >= 2:
                sd = number(parameter_column(p, "sd"), r[parameter_column(p, "sd")], at, minimum=0.0)
                half = float(student_t.ppf(0.975, n - 1)) * sd / math.sqrt(n)
                low, high = mean - half, mean + half
            else:
                low = high = math.nan
            row.update({parameter_column(p, "mean"): mean, parameter_column(p, "ci95_low"): low,
                        parameter_column(p, "ci95_high"): high})
        row["vaf_pct_mean"] = number("vaf_pct_mean", r["vaf_pct_mean"], at)
        rows.append(row)
    return pd.DataFrame(rows, columns=out_columns)


def truth_recovery(impedance: pd.DataFrame, source: str = "") -> pd.DataFrame:
    """Estimated against true K and D of the subjects with a known truth (synthetic), per joint.

    Parameters
    ----------
    impedance : pandas.DataFrame
        ``results/tables/impedance.tsv`` (:data:`loper_analysis.impedance.IMPEDANCE_COLUMNS`):
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
        ``K_n_within_tolerance`` (:data:`loper_analysis.impedance.TRUTH_TOLERANCE`, the rule of the
        across-subject summary) and
        ``K_n_truth_in_ci95`` (the truth inside the fit's 95 % CI, bounds
        included); the same for D. No truth known: no rows.

    Raises
    ------
    LoperInputError
        A column missing, or a fitted row whose estimate, CI bound or error
        is no finite number (naming the row and the column).
    """
    needed = ["subject", "onset_ms", "joint", "status",
              *(parameter_column(p, w) for p in _PARAMETERS for w in ("", "ci95_low", "ci95_high", "true", "error"))]
    counts = ["n_fits", "n_failed"]
    per_p = [(p, w) for p in _PARAMETERS for w in ("error_mean", "error_median_abs")]
    columns = ["joint", "n_subjects", *counts, *(parameter_column(p, w) for p, w in per_p),
               *(f"{p}_{w}" for p in _PARAMETERS for w in ("error_median_abs_pct", "n_within_tolerance",
                                                              "n_truth_in_ci95"))]
    table = _rows_or_empty(impedance, needed, source, "impedance table")
    known = table[pd.to_numeric(table[parameter_column("K", "true")], errors="coerce").notna()].reset_index(drop=True)
    fitted = known[known["status"].isin(FITTED_STATUSES)].reset_index(drop=True)
    values = {}
    for p in _PARAMETERS:
        for w in ("", "ci95_low", "ci95_high", "true", "error"):
            col = parameter_column(p, w)
            values[col] = _numbers(fitted, col, f"{where(source)}fitted rows")
    rows = []
    for joint in [j for j in JOINTS if j in set(known["joint"])] + sorted(set(known["joint"]) - set(JOINTS)):
        own = (fitted["joint"] == joint).to_numpy()
        row = {"joint": joint, "n_subjects": int(known.loc[known["joint"] == joint, "subject"].nunique()),
               "n_fits": int(own.sum()), "n_failed": int((known["joint"] == joint).sum() - own.sum())}
        for p in _PARAMETERS:
            err = values[parameter_column(p, "error")][own]
            true = values[parameter_column(p, "true")][own]
            rel, ab = TRUTH_TOLERANCE[p]
            low, high = values[parameter_column(p, "ci95_low")][own], values[parameter_column(p, "ci95_high")][own]
            nonzero = true != 0
            rel_err = np.abs(err[nonzero]) / np.abs(true[nonzero]) * 100.0
            row.update({
                parameter_column(p, "error_mean"): float(err.mean()) if err.size else math.nan,
                parameter_column(p, "error_median_abs"): float(np.median(np.abs(err))) if err.size else math.nan,
                f"{p}_error_median_abs_pct": float(np.median(rel_err)) if rel_err.size else math.nan,
                f"{p}_n_within_tolerance": int((np.abs(err) <= np.maximum(rel * np.abs(true), ab)).sum()),
                f"{p}_n_truth_in_ci95": int(((true >= low) & (true <= high)).sum()),
            })
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
    needed = ["subject", "phase", "joint", "rmsd_rad", "isv_ave_rad", "transparent", "study_rmsd_rad",
              "study_isv_ave_rad"]
    columns = ["phase", "joint", "rmsd_rad", "isv_ave_rad", "transparent", "study_rmsd_rad", "study_isv_ave_rad",
               "n_subjects", "n_subjects_transparent"]
    table = _rows_or_empty(rmsd, needed, source, "transparency table")
    verdicts = [_bool_or_none(v, "transparent", f"{where(source)}row {i}")
                for i, v in enumerate(table["transparent"].to_numpy())]
    table = table.assign(transparent=verdicts, subject=table["subject"].astype(str))
    rows = []
    for i, r in table[table["subject"] == "all"].iterrows():
        at = f"{where(source)}row {i} (all {r['phase']} {r['joint']})"
        subjects = table[(table["subject"] != "all") & (table["phase"] == r["phase"])
                         & (table["joint"] == r["joint"])]["transparent"]
        judged = [v for v in subjects if v is not None]
        rows.append({
            "phase": r["phase"], "joint": r["joint"],
            **{c: (math.nan if pd.isna(r[c]) else number(c, r[c], at)) for c in ("rmsd_rad", "isv_ave_rad")},
            "transparent": r["transparent"],
            **{c: (math.nan if pd.isna(r[c]) else number(c, r[c], at)) for c in ("study_rmsd_rad",
                                                                                 "study_isv_ave_rad")},
            "n_subjects": len(judged), "n_subjects_transparent": int(sum(judged)),
        })
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
            raise LoperInputError(f"{where(source)}device summary: metric {metric!r} missing "
                                  f"(has {sorted(by_metric)})")
        value = number(f"value of metric {metric!r}", by_metric[metric], source)
        rows.append({"metric": metric, "value": value, "study_value": study, "unit": unit,
                     "difference_pct": (value / study - 1.0) * 100.0})
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
    for p in _PARAMETERS:
        g = clean[clean["parameter"].astype(str).str.startswith(f"{p}_")]
        if not len(g):
            continue
        at = f"{where(source)}no_noise {p} rows"
        lo, hi = _numbers(g, "min_error", at), _numbers(g, "max_error", at)
        s_lo, s_hi = _numbers(g, "study_min_error", at), _numbers(g, "study_max_error", at)
        rows.append({"parameter": p, "n_combinations": integer("n", int(_numbers(g, "n", at).min()), at),
                     "min_error": float(lo.min()), "max_error": float(hi.max()),
                     "study_min_error": float(s_lo.min()), "study_max_error": float(s_hi.max()),
                     "within_study": bool(lo.min() >= s_lo.min() and hi.max() <= s_hi.max())})
    return pd.DataFrame(rows, columns=["parameter", "n_combinations", "min_error", "max_error", "study_min_error",
                                       "study_max_error", "within_study"])


# ---------------------------------------------------------------------------------------------- the run


@dataclass(frozen=True)
class RunSettings:
    """The settings of a run the front page lists (the workflow's configuration; units in the names)."""

    seed: int
    perturbation_onsets_ms: Sequence[int]
    perturbation_repeats: int
    perturbed_side: str
    filter_cutoff_hz: float
    filter_order: int
    window_before_s: float
    window_after_s: float
    stiffness_bounds_nm_per_rad: Sequence[float]
    damping_bounds_nms_per_rad: Sequence[float]
    n_starts: int
    noise_model: str
    null_pair_components: int
    synthetic_variability: str
    synthetic_walking_duration_s: float
    pulse_force_n: float
    pulse_duration_s: float

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) of every setting, as the page shows them."""
        onsets = ", ".join(str(int(o)) for o in self.perturbation_onsets_ms)
        k_lo, k_hi = self.stiffness_bounds_nm_per_rad
        d_lo, d_hi = self.damping_bounds_nms_per_rad
        noise = (f"null pairs ({self.null_pair_components} deviation shapes projected out)"
                 if self.noise_model == "null_pairs" else f"{self.noise_model} (plain least squares)")
        return [
            ("perturbations", f"onsets {onsets} ms after {self.perturbed_side} toe-off, "
                              f"{self.perturbation_repeats} trials per onset"),
            ("fit window", f"{_g(self.window_before_s * 1000)} ms before to {_g(self.window_after_s * 1000)} ms "
                           f"after onset"),
            ("bounds", f"K {_g(k_lo)}–{_g(k_hi)} N·m/rad, D {_g(d_lo)}–{_g(d_hi)} N·m·s/rad; "
                       f"{self.n_starts} random starts"),
            ("noise model", noise),
            ("filter", f"Butterworth low-pass {_g(self.filter_cutoff_hz)} Hz, order {self.filter_order}, zero phase"),
            ("synthetic lab", f"{_g(self.synthetic_walking_duration_s)} s per walking trial, pulses of "
                              f"{_g(self.pulse_force_n)} N for {_g(self.pulse_duration_s * 1000)} ms, "
                              f"variability '{self.synthetic_variability}'"),
            ("seed", str(self.seed)),
        ]


def _g(value: float) -> str:
    """A setting's number without trailing zeros (``40``, ``0.1``, ``12.5``)."""
    return f"{float(value):g}".replace("-", _MINUS)


def _subject_line(subjects: Mapping[str, str], trials: Mapping[str, Sequence[str]]) -> str:
    """'3 synthetic (S01, S02, S03) + 0 recorded subjects, 8 walking trials each' (HTML)."""
    parts = []
    for source in ("synthetic", "recorded"):
        names = [s for s, src in subjects.items() if src == source]
        listed = f" ({html.escape(', '.join(names))})" if names else ""
        parts.append(f"{len(names)} {source}{listed}")
    counts = sorted({len(t) for t in trials.values()})
    if not counts:
        per = "no walking trials processed"
    elif len(counts) == 1:
        per = f"{counts[0]} walking trials each"
    else:
        per = f"{counts[0]}–{counts[-1]} walking trials per subject"
    return f"{parts[0]} + {parts[1]} subjects, {per}"


# ---------------------------------------------------------------------------------------------- formatting


def _decimals(values, significant: int = 3, most: int = 4) -> int:
    """Decimals that show the largest magnitude among ``values`` with ``significant`` digits (0 to ``most``)."""
    finite = np.abs(np.asarray([v for v in values if v is not None], dtype=float))
    finite = finite[np.isfinite(finite) & (finite > 0)]
    if not finite.size:
        return 2
    return int(min(most, max(0, significant - 1 - math.floor(math.log10(finite.max())))))


def _text(value: float, decimals: int) -> str:
    """A number with ``decimals`` decimals and a true minus sign; no negative zero; NaN as an en dash."""
    if value is None or not math.isfinite(value):
        return "–"
    text = f"{value:.{decimals}f}"
    if float(text) == 0.0:
        text = text.lstrip("-")
    return text.replace("-", _MINUS)


def _num(value, decimals: int, key: str) -> str:
    """A number as a ``<span>`` carrying its key (``table|row|column``) and full-precision value."""
    value = math.nan if value is None else float(value)
    return f'<span data-q="{html.escape(key)}" data-v="{value!r}">{_text(value, decimals)}</span>'


def _count(value: int, key: str) -> str:
    return f'<span data-q="{html.escape(key)}" data-v="{int(value)!r}">{int(value)}</span>'


def _mark(ok: bool | None) -> str:
    """✓ (green), ✗ (red) or a grey dot (no criterion or no verdict)."""
    if ok is None:
        return '<span class="lf-mark lf-dim">●</span>'
    return '<span class="lf-mark lf-ok">✓</span>' if ok else '<span class="lf-mark lf-bad">✗</span>'


def _pct(n: int, total: int) -> str:
    return f"{100.0 * n / total:.0f} %" if total else "–"


#: The fragment's style: every rule under ``.lf`` but the first, which top-aligns the report's content pane while
#: it holds the front page (Snakemake centres it vertically, so a Workflow panel taller than the screen would
#: lose its top, out of reach of the scroll bar).
_STYLE = """<style>
.h-screen.overflow-auto.items-center:has(.lf){align-items:flex-start}
.lf{font-size:12.5px;line-height:1.4;color:#1f2937;margin:0 0 10px}
.lf h2{font-size:14px;font-weight:700;margin:10px 0 3px;line-height:1.3;color:#111827}
.lf p{margin:2px 0 4px}
.lf ul.lf-verdicts{list-style:none;padding:0;margin:2px 0 6px}
.lf ul.lf-verdicts li{margin:1px 0;padding:0 0 0 18px;text-indent:-18px}
.lf .lf-mark{display:inline-block;width:18px;text-indent:0;text-align:center}
.lf table{border-collapse:collapse;margin:2px 0 8px;font-size:12px;line-height:1.3;width:auto}
.lf th,.lf td{padding:1px 5px;text-align:right;border:0;border-bottom:1px solid #e5e7eb;white-space:nowrap;
 font-variant-numeric:tabular-nums;vertical-align:baseline}
.lf thead th{font-weight:600;color:#374151;border-bottom:1px solid #9ca3af;vertical-align:bottom}
.lf .lf-l{text-align:left}
.lf caption{caption-side:top;text-align:left;font-weight:700;font-size:12.5px;padding:0 0 1px;color:#111827}
.lf .lf-ok{color:#15803d;font-weight:700}
.lf .lf-bad{color:#b91c1c;font-weight:700}
.lf .lf-dim,.lf .lf-note{color:#6b7280}
.lf .lf-note{font-size:11px;margin:0 0 6px}
.lf tr.lf-sep td{border-top:1px solid #9ca3af}
.lf img{max-width:100%;height:auto;margin:4px 0 2px}
</style>"""


# ------------------------------------------------------------------------------------------ the sections


def _summary_table(ci: pd.DataFrame) -> str:
    """Across-subject mean [95 % CI] of K and D, VAF and counts, per joint and onset."""
    dec = {}
    for p in _PARAMETERS:
        cols = [parameter_column(p, w) for w in ("mean", "ci95_low", "ci95_high")]
        for joint in set(ci["joint"]):
            dec[p, joint] = _decimals(ci.loc[ci["joint"] == joint, cols].to_numpy().ravel())
    body = []
    for joint, g in ci.groupby("joint", sort=False):
        for k, r in enumerate(g.to_dict("records")):
            key = f"impedance-summary|{joint}|{r['onset_ms']}|"
            cells = [f'<td class="lf-l" rowspan="{len(g)}">{html.escape(str(joint))}</td>' if k == 0 else "",
                     f"<td>{_count(r['onset_ms'], key + 'onset_ms')}</td>"]
            for p in _PARAMETERS:
                d = dec[p, joint]
                mean, low, high = (parameter_column(p, w) for w in ("mean", "ci95_low", "ci95_high"))
                interval = f"[{_num(r[low], d, key + low)}, {_num(r[high], d, key + high)}]"
                cells.append(f'<td>{_num(r[mean], d, key + mean)} <span class="lf-dim">{interval}</span></td>')
            cells.append(f"<td>{_num(r['vaf_pct_mean'], 0, key + 'vaf_pct_mean')}</td>")
            n = _count(r["n_subjects"], key + "n_subjects")
            if r["n_not_identifiable"]:
                n += f' <span class="lf-dim">({_count(r["n_not_identifiable"], key + "n_not_identifiable")})</span>'
            cells.append(f"<td>{n}</td>")
            sep = ' class="lf-sep"' if k == 0 and body else ""
            body.append(f"<tr{sep}>{''.join(cells)}</tr>")
    study = "; ".join(f"{j} K {_g(v['K'][0])}–{_g(v['K'][1])}, D {_g(v['D'][0])}–{_g(v['D'][1])}"
                      for j, v in STUDY_SWING_IMPEDANCE.items())
    return (
        '<table id="lf-impedance-summary"><caption>Impedance: across-subject mean [95 % CI of the mean]</caption>'
        '<thead><tr><th class="lf-l">joint</th><th>onset<br>ms</th><th>K<br>N·m/rad</th><th>D<br>N·m·s/rad</th>'
        '<th>VAF<br>%</th><th>subjects<br><span class="lf-dim">(not ident.)</span></th></tr></thead>'
        f"<tbody>{''.join(body)}</tbody></table>"
        '<p class="lf-note">Onset after toe-off. CI: Student t, n − 1 df. “Not ident.”: fits whose CI holds 0 and '
        f"the plausible range (in the mean). The study’s across-subject means: {study}.</p>"
    )


def _truth_table(truth: pd.DataFrame) -> str:
    """Bias, median |error|, within tolerance and truth inside the CI, per parameter and joint."""
    body = []
    for p in _PARAMETERS:
        bias, median = parameter_column(p, "error_mean"), parameter_column(p, "error_median_abs")
        pct, within, inside = f"{p}_error_median_abs_pct", f"{p}_n_within_tolerance", f"{p}_n_truth_in_ci95"
        d = _decimals(truth[[bias, median]].to_numpy().ravel())
        for k, r in enumerate(truth.to_dict("records")):
            key = f"truth-recovery|{p}_{r['joint']}|"
            n = r["n_fits"]
            sep = ' class="lf-sep"' if k == 0 and body else ""
            body.append(
                f'<tr{sep}><td class="lf-l">{p}<sub>{html.escape(str(r["joint"]))}</sub></td>'
                f"<td>{_count(n, key + 'n_fits')}</td>"
                f"<td>{_num(r[bias], d, key + bias)}</td>"
                f'<td>{_num(r[median], d, key + median)} <span class="lf-dim">({_num(r[pct], 0, key + pct)} %)'
                "</span></td>"
                f"<td>{_count(r[within], key + within)}/{n}</td>"
                f"<td>{_count(r[inside], key + inside)}/{n}</td></tr>")
    k_rel, k_abs = TRUTH_TOLERANCE["K"]
    d_rel, d_abs = TRUTH_TOLERANCE["D"]
    return (
        '<table id="lf-truth-recovery"><caption>Truth recovery: estimate − truth</caption>'
        '<thead><tr><th class="lf-l"></th><th>fits</th><th>mean<br>error</th><th>median |error|<br>'
        '<span class="lf-dim">(% of truth)</span></th><th>within<br>tolerance</th><th>truth in<br>95 % CI</th>'
        f"</tr></thead><tbody>{''.join(body)}</tbody></table>"
        '<p class="lf-note">Synthetic subjects, over subjects and onsets; K in N·m/rad, D in N·m·s/rad. '
        f"Tolerance: {k_rel * 100:g} % of the truth or {_g(k_abs)} N·m/rad for K, {d_rel * 100:g} % or "
        f"{_g(d_abs)} N·m·s/rad for D. Fits: status ok or not identifiable.</p>"
    )


def _transparency_table(tr: pd.DataFrame) -> str:
    """Group RMSD against ISV_ave per phase and joint, with the study's values."""
    d = 3
    body = []
    for r in tr.to_dict("records"):
        key = f"transparency|{r['phase']}|{r['joint']}|"
        study = (f"{_num(r['study_rmsd_rad'], d, key + 'study_rmsd_rad')} / "
                 f"{_num(r['study_isv_ave_rad'], d, key + 'study_isv_ave_rad')}")
        body.append(
            f'<tr><td class="lf-l">{html.escape(str(r["phase"]))}</td>'
            f'<td class="lf-l">{html.escape(str(r["joint"]))}</td>'
            f"<td>{_num(r['rmsd_rad'], d, key + 'rmsd_rad')}</td>"
            f"<td>{_num(r['isv_ave_rad'], d, key + 'isv_ave_rad')}</td>"
            f"<td>{_mark(r['transparent'])}</td>"
            f"<td>{_count(r['n_subjects_transparent'], key + 'n_subjects_transparent')}/{r['n_subjects']}</td>"
            f'<td class="lf-dim">{study}</td></tr>')
    return (
        '<table id="lf-transparency"><caption>Transparency: RMSD with vs without the device (rad)'
        '</caption><thead><tr><th class="lf-l">phase</th><th class="lf-l">joint</th><th>RMSD</th><th>ISV_ave</th>'
        '<th>RMSD &lt;<br>ISV_ave</th><th>subjects</th><th>study<br>RMSD / ISV_ave</th></tr></thead>'
        f"<tbody>{''.join(body)}</tbody></table>"
    )


#: How the device table names the study's metrics.
_DEVICE_NAMES = {"bandwidth_hz": "−3 dB bandwidth", "rise_time_ms": "rise time 10–90 %",
                 "overshoot_pct": "overshoot", "steady_state_40n_n": "steady state, 40 N steps"}


def _device_table(dev: pd.DataFrame) -> str:
    """Our device figures beside the study's."""
    body = []
    for r in dev.to_dict("records"):
        key = f"device|{r['metric']}|"
        body.append(
            f'<tr><td class="lf-l">{html.escape(_DEVICE_NAMES.get(r["metric"], r["metric"]))}</td>'
            f"<td>{_num(r['value'], 1, key + 'value')}</td>"
            f"<td>{_num(r['study_value'], 1, key + 'study_value')}</td>"
            f'<td class="lf-l">{html.escape(r["unit"])}</td>'
            f"<td>{_num(r['difference_pct'], 1, key + 'difference_pct')}</td></tr>")
    return (
        '<table id="lf-device"><caption>Device: force controller, free-hanging leg</caption>'
        '<thead><tr><th class="lf-l"></th><th>ours</th><th>study</th><th></th><th>difference<br>%</th></tr>'
        f"</thead><tbody>{''.join(body)}</tbody></table>"
    )


# ------------------------------------------------------------------------------------------------ verdicts


def _truth_verdict(truth: pd.DataFrame) -> str:
    """'✓ Truth recovered (3 synthetic subjects, 26 joint fits): in the 95 % CI 47/52 ...; within tolerance ...'."""
    n_fits = int(truth["n_fits"].sum())
    n_failed = int(truth["n_failed"].sum())
    inside = int(truth["K_n_truth_in_ci95"].sum() + truth["D_n_truth_in_ci95"].sum())
    total = 2 * n_fits
    p = ci_coverage_p(inside, total)
    ok = None if total == 0 else bool(p >= 0.05)
    failed = f", {n_failed} failed" if n_failed else ""
    within = ", ".join(
        f"{q} {_count(int(truth[q + '_n_within_tolerance'].sum()), 'verdict|truth|' + q + '_n_within_tolerance')}"
        f"/{n_fits}" for q in _PARAMETERS)
    word = "Truth recovered" if ok else ("Truth missed" if ok is False else "Truth")
    coverage = "no joint fitted"
    if total:
        judged = "as expected of 95 %" if ok else "fewer than 95 % allow"
        coverage = (f"inside the 95 % CI {_count(inside, 'verdict|truth|n_truth_in_ci95')}/{total} "
                    f"({_pct(inside, total)}, {judged}: binomial p = {p:.2f}); within tolerance {within}")
    n_subjects = int(truth["n_subjects"].max())
    return (f"<li>{_mark(ok)}<b>{word}</b> ({n_subjects} synthetic subject{'s' if n_subjects != 1 else ''}, "
            f"{n_fits} joint fits{failed}): {coverage}.</li>")


def _transparency_verdict_line(tr: pd.DataFrame) -> str:
    """'✓ Transparent: RMSD < ISV_ave in 6/6 phase × joint, 18/18 per subject'."""
    judged = [v for v in tr["transparent"] if v is not None]
    n_ok = int(sum(judged))
    ok = None if not judged else n_ok == len(judged)
    word = "Transparent" if ok else ("Not transparent everywhere" if ok is False else "Transparency not judged")
    subjects = (f"{_count(int(tr['n_subjects_transparent'].sum()), 'verdict|transparency|n_subjects_transparent')}"
                f"/{int(tr['n_subjects'].sum())}")
    return (f"<li>{_mark(ok)}<b>{word}</b>: RMSD &lt; ISV_ave in "
            f"{_count(n_ok, 'verdict|transparency|n_transparent')}/{len(tr)} phase × joint, {subjects} per "
            f"subject.</li>")


def _device_verdict_line(dev: pd.DataFrame) -> str:
    """'● Device as in the study: 4 figures within 3.4 %; bandwidth 38.8 Hz (study 39)'."""
    worst = float(dev["difference_pct"].abs().max())
    band = dev[dev["metric"] == "bandwidth_hz"]
    bandwidth = ""
    if len(band):
        bandwidth = (f"; bandwidth {_num(band['value'].iloc[0], 1, 'verdict|device|bandwidth_hz')} Hz "
                     f"(study {_g(band['study_value'].iloc[0])})")
    return (f"<li>{_mark(None)}<b>Device</b> as in the study: {len(dev)} figures within "
            f"{_num(worst, 1, 'verdict|device|max_abs_difference_pct')} %{bandwidth}.</li>")


def _validation_verdict_line(val: pd.DataFrame) -> str:
    """'✓ Validation without noise (729 combinations): |error| ≤ 0.035 N·m/rad ... (study ≤ 0.87 ...)'."""
    ok = bool(val["within_study"].all())
    parts, study = [], []
    for r in val.to_dict("records"):
        p = r["parameter"]
        worst = max(abs(r["min_error"]), abs(r["max_error"]))
        d = _decimals([worst], significant=2, most=6)
        parts.append(f"{_num(worst, d, 'verdict|validation|' + p + '_max_abs_error')} {_UNIT[p]} ({p})")
        study.append(_g(max(abs(r["study_min_error"]), abs(r["study_max_error"]))))
    n = int(val["n_combinations"].min())
    return (f"<li>{_mark(ok)}<b>Validation</b> without noise ({n} combinations): |error| ≤ {', '.join(parts)}; "
            f"the study ≤ {' and '.join(study)}.</li>")


# ------------------------------------------------------------------------------------------------ the page


def front_page_html(subjects: Mapping[str, str], trials: Mapping[str, Sequence[str]], settings: RunSettings,
                    versions: Mapping[str, str], device: pd.DataFrame, validation: pd.DataFrame,
                    summary: pd.DataFrame | None = None, truth: pd.DataFrame | None = None,
                    impedance_status: Mapping[str, int] | None = None, figure_png: bytes | None = None,
                    transparency: pd.DataFrame | None = None) -> str:
    """The front page as one HTML fragment (a ``<style>`` and a ``<div class="lf">``).

    Parameters
    ----------
    subjects : Mapping[str, str]
        Subject -> ``synthetic`` or ``recorded``, in the subject sheet's order.
    trials : Mapping[str, Sequence[str]]
        Processed subject -> its walking trials.
    settings : RunSettings
        The run's settings.
    versions : Mapping[str, str]
        Software -> version, in the order to show (Python and :data:`SOFTWARE`).
    device : pandas.DataFrame
        :func:`device_comparison`.
    validation : pandas.DataFrame
        :func:`validation_verdict`.
    summary : pandas.DataFrame or None
        :func:`impedance_summary_ci`; None: the run had no perturbation trials.
    truth : pandas.DataFrame or None
        :func:`truth_recovery`; None or no rows: no subject with a known truth.
    impedance_status : Mapping[str, int] or None
        Status -> number of rows of the impedance table (shown when nothing was fitted).
    figure_png : bytes or None
        The main figure (``results/figures/impedance.png``), embedded as a data URI.
    transparency : pandas.DataFrame or None
        :func:`transparency_verdict`; None: no subject walked both trials of the transparency pair.

    Returns
    -------
    str
        The fragment, ending in a newline. It holds no time, host or path.
    """
    if not isinstance(settings, RunSettings):
        raise LoperInputError(f"settings must be a RunSettings, got {type(settings).__name__}")
    parts = [_STYLE, '<div class="lf">']
    onsets = ", ".join(str(int(o)) for o in settings.perturbation_onsets_ms)
    parts.append(f"<p><b>Run</b>: {_subject_line(subjects, trials)} (onsets {onsets} ms × "
                 f"{settings.perturbation_repeats} + the transparency pair); seed {settings.seed}; settings and "
                 "versions at the end.</p>")
    verdicts = []
    has_truth = truth is not None and len(truth) > 0
    if has_truth:
        verdicts.append(_truth_verdict(truth))
    if transparency is not None and len(transparency):
        verdicts.append(_transparency_verdict_line(transparency))
    if len(device):
        verdicts.append(_device_verdict_line(device))
    if len(validation):
        verdicts.append(_validation_verdict_line(validation))
    parts.append(f'<ul class="lf-verdicts">{"".join(verdicts)}</ul>')
    if summary is None:
        parts.append("<p>No perturbation trials in this run: no impedance was identified.</p>")
    elif not len(summary):
        status = ", ".join(f"{n} {html.escape(s)}" for s, n in (impedance_status or {}).items())
        parts.append(f'<p id="lf-impedance-summary"><b>Impedance</b>: no joint was fitted '
                     f"({status or 'no rows'}; the reasons are in results/tables/impedance.tsv).</p>")
    else:
        parts.append(_summary_table(summary))
    if has_truth and truth["n_fits"].sum() > 0:
        parts.append(_truth_table(truth))
    if figure_png:
        data = base64.b64encode(figure_png).decode("ascii")
        parts.append('<h2>K and D per onset</h2>'
                     f'<img id="lf-figure" alt="Stiffness K and damping D per onset: subjects, mean and truth" '
                     f'src="data:image/png;base64,{data}">'
                     '<p class="lf-note">Grey: each subject; black: the across-subject mean; open circles: the '
                     "truth of synthetic subjects.</p>")
    if transparency is not None and len(transparency):
        parts.append(_transparency_table(transparency))
    if len(device):
        parts.append(_device_table(device))
    rows = "".join(f'<tr><td class="lf-l">{html.escape(k)}</td><td class="lf-l">{html.escape(v)}</td></tr>'
                   for k, v in settings.rows())
    software = " · ".join(f"{html.escape(k)} {html.escape(v)}" for k, v in versions.items())
    parts.append('<table id="lf-run"><caption>What was run</caption><tbody>'
                 f'<tr><td class="lf-l">subjects</td><td class="lf-l">{_subject_line(subjects, trials)}</td></tr>'
                 f'{rows}<tr><td class="lf-l">software</td><td class="lf-l" style="white-space:normal">'
                 f"{software}</td></tr></tbody></table>")
    parts.append("</div>")
    return "\n".join(parts) + "\n"
