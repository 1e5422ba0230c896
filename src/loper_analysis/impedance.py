"""Impedance per subject and onset: the fit of the mean response, its table rows, and the aggregates.

The fit (DESIGN.md section 5) runs :func:`loper_analysis.identification.identify_impedance`
on the subject's mean perturbed and matched unperturbed swing (from
:mod:`loper_analysis.responses`), with the subject's segment table and the
rod force along the brace normal. A row per joint reports K, D, their 95 %
confidence intervals, the VAF, the number of strides, the truth of a
synthetic subject and a status:

* ``ok``;
* ``not_identifiable``: the 95 % CI of K or D spans more than
  ``max_ci_fraction`` of its bound range (typically the ankle, whose small
  torques barely move the prediction error);
* ``missing``: no trial of that onset;
* ``failed``: too few strides, or the optimiser did not converge; ``reason`` says why.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from .constants import JOINTS
from .errors import LoperInputError

__all__ = [
    "IMPEDANCE_COLUMNS",
    "brace_force_direction",
    "impedance_rows",
    "status_rows",
    "fit_subject_onset",
    "LITERATURE",
    "impedance_summary",
    "literature_table",
]

#: Columns of ``results/impedance/{subject}/{onset}.tsv`` and ``results/tables/impedance.tsv``.
IMPEDANCE_COLUMNS: tuple[str, ...] = (
    "subject", "onset_ms", "joint", "K", "D", "K_ci95_low", "K_ci95_high", "D_ci95_low", "D_ci95_high",
    "vaf_pct", "n_strides", "K_true", "D_true", "K_error", "D_error", "cost_rad2", "noise_model", "n_null_pairs",
    "status", "reason",
)


def brace_force_direction(markers_m: np.ndarray, labels: Sequence[str], brace=("LBRA_P", "LBRA_D"),
                          source: str = "") -> np.ndarray:
    """Unit vectors (n, 2), world x/y of the model frame, along which the rods push.

    The two brace markers lie on the thigh, proximal and distal; the rods push
    perpendicular to their line, forward: the proximal-minus-distal direction
    turned by -90 degrees in the sagittal (x, y) plane. ``markers_m`` is
    (n, n_markers, 3) in the model frame (X forward, Y up), e.g. a TRC of the
    pipeline.
    """
    labels = list(labels)
    missing = [b for b in brace if b not in labels]
    if missing:
        raise LoperInputError(f"{source}: brace marker(s) {missing} not in the marker data")
    p = markers_m[:, labels.index(brace[0]), :2]
    d = markers_m[:, labels.index(brace[1]), :2]
    up = p - d
    norm = np.linalg.norm(up, axis=1)
    if not np.all(np.isfinite(norm)) or np.any(norm < 1e-3):
        bad = int(np.argmax(~np.isfinite(norm) | (norm < 1e-3)))
        raise LoperInputError(f"{source}: brace markers {brace} missing or coincident at frame {bad}")
    up /= norm[:, None]
    return np.stack([up[:, 1], -up[:, 0]], axis=-1)


def impedance_rows(fit, subject: str, onset_ms: int, n_strides: int, truth: Mapping | None = None,
                   lower=(0.0, 0.0), upper=(200.0, 10.0), max_ci_fraction: float = 0.5,
                   noise_model: str = "white", n_null_pairs: int = 0, note: str = "") -> pd.DataFrame:
    """One row per joint from an :class:`~loper_analysis.identification.ImpedanceFit` (columns :data:`IMPEDANCE_COLUMNS`).

    ``truth``: ``{joint: {"K": .., "D": ..}}`` of a synthetic subject (errors
    = estimate - truth), None for a recorded one. ``noise_model`` (``white`` |
    ``null_pairs``) and ``n_null_pairs`` say how the fit weighted its errors;
    ``note`` is appended to every row's reason.
    """
    rows = []
    span = np.array(upper, float) - np.array(lower, float)
    for j, joint in enumerate(JOINTS):
        k, d = 2 * j, 2 * j + 1
        row = {
            "subject": subject, "onset_ms": int(onset_ms), "joint": joint,
            "K": fit.estimate[k], "D": fit.estimate[d],
            "K_ci95_low": fit.ci95_low[k], "K_ci95_high": fit.ci95_high[k],
            "D_ci95_low": fit.ci95_low[d], "D_ci95_high": fit.ci95_high[d],
            "vaf_pct": fit.vaf_pct[j], "n_strides": int(n_strides), "cost_rad2": fit.cost,
            "noise_model": noise_model, "n_null_pairs": int(n_null_pairs),
        }
        if truth is not None:
            row.update(K_true=truth[joint]["K"], D_true=truth[joint]["D"],
                       K_error=row["K"] - truth[joint]["K"], D_error=row["D"] - truth[joint]["D"])
        widths = np.array([row["K_ci95_high"] - row["K_ci95_low"], row["D_ci95_high"] - row["D_ci95_low"]])
        if not fit.success:
            row.update(status="failed", reason=f"optimiser did not converge: {fit.message}")
        elif not np.all(np.isfinite(widths)) or np.any(widths > max_ci_fraction * span):
            row.update(status="not_identifiable",
                       reason=f"95 % CI width K {widths[0]:.3g} N·m/rad, D {widths[1]:.3g} N·m·s/rad exceeds "
                              f"{max_ci_fraction:g} of the bounds")
        else:
            row.update(status="ok", reason="")
        if note:
            row["reason"] = "; ".join(r for r in (row["reason"], note) if r)
        rows.append(row)
    return pd.DataFrame(rows).reindex(columns=IMPEDANCE_COLUMNS)


def status_rows(subject: str, onset_ms: int, status: str, reason: str, n_strides: int = 0,
                truth: Mapping | None = None) -> pd.DataFrame:
    """Rows without a fit (``missing`` or ``failed``), one per joint, estimates empty."""
    rows = []
    for joint in JOINTS:
        row = {"subject": subject, "onset_ms": int(onset_ms), "joint": joint, "n_strides": int(n_strides),
               "status": status, "reason": reason}
        if truth is not None:
            row.update(K_true=truth[joint]["K"], D_true=truth[joint]["D"])
        rows.append(row)
    return pd.DataFrame(rows).reindex(columns=IMPEDANCE_COLUMNS)


def fit_subject_onset(
    trials: Sequence[Mapping],
    segments_tsv,
    onset_ms: int,
    subject: str,
    response_out,
    counts_out,
    fit_out,
    curves_out,
    truth_yaml=None,
    *,
    null_trials: Sequence[Mapping] = (),
    noise_model: str = "null_pairs",
    null_pair_components: int = 6,
    min_null_pairs: int = 30,
    rate_hz: float = 128.0,
    window_before_s: float = 0.025,
    window_after_s: float = 0.25,
    initial_state_span_s: float = 0.1,
    initial_state_degree: int = 1,
    n_starts: int = 10,
    n_substeps: int = 2,
    tolerance: float = 1e-6,
    merge_tolerance: float = 0.01,
    stiffness_bounds=(0.0, 200.0),
    damping_bounds=(0.0, 10.0),
    whisker: float = 1.5,
    max_fraction: float = 0.2,
    min_strides: int = 5,
    max_ci_fraction: float = 0.5,
    seed=0,
) -> pd.DataFrame:
    """Responses and the impedance fit of one subject at one onset, from the trials' files.

    ``trials``: one mapping per trial with ``name``, ``angles``, ``strides``,
    ``force`` (TSV paths of the processing rules) and ``markers`` (the TRC,
    for the brace markers). No trial: every output says ``missing``. Writes
    the mean response (:func:`loper_analysis.responses.subject_onset_response`),
    the stride counts, the fit rows (:data:`IMPEDANCE_COLUMNS`) and the
    measured and model responses of the fit (``curves_out``, rad).

    ``noise_model``: ``white`` fits the plain least squares of the study;
    ``null_pairs`` fits it first, then takes the null pairs
    (:func:`loper_analysis.responses.null_pair_windows` over ``null_trials``:
    ``name``, ``angles``, ``strides``, e.g. all the subject's walking trials
    with the device; the onset's own trials when empty), their prediction
    errors at that estimate
    (:func:`loper_analysis.identification.null_pair_errors`), projects their
    ``null_pair_components`` dominant shapes out of the prediction error
    (:func:`loper_analysis.identification.nuisance_projection`) and fits again
    from the first estimate and the random starts, with CI from the null
    pairs' covariance divided by the number of averaged pairs. With fewer
    than ``min_null_pairs`` null pairs the first fit stands and the reason
    says so.
    """
    import warnings

    from .dynamics import SegmentParameters
    from .gait import TooFewStridesWarning
    from dataclasses import replace

    from .identification import identify_impedance, null_pair_errors, nuisance_projection, prepare_window
    from .io.tables import read_markers
    from .processing import write_tsv
    from .responses import null_pair_windows, subject_onset_response

    if noise_model not in ("null_pairs", "white"):
        raise LoperInputError(f"identification.noise_model must be 'null_pairs' or 'white', got {noise_model!r}")
    truth = None
    if truth_yaml:
        from .synthetic.subjects import read_truth

        all_truth = read_truth(truth_yaml)
        truth = all_truth.get(int(onset_ms))
    if not trials:
        write_tsv(pd.DataFrame(), response_out)
        write_tsv(pd.DataFrame([{"trial": "total", "status": "missing", "reason": "no trial of this onset"}]), counts_out)
        rows = status_rows(subject, onset_ms, "missing", "no trial of this onset", truth=truth)
        write_tsv(rows, fit_out)
        write_tsv(pd.DataFrame(columns=["time_s"]), curves_out)
        return rows
    inputs = []
    for tr in trials:
        angles = pd.read_csv(tr["angles"], sep="\t")
        t, X, labels = read_markers(tr["markers"])
        if len(t) != len(angles) or not np.allclose(t, angles["time_s"].to_numpy(), atol=1e-6):
            raise LoperInputError(f"{tr['markers']}: frames differ from {tr['angles']}")
        inputs.append({
            "name": tr["name"], "angles": angles, "strides": pd.read_csv(tr["strides"], sep="\t"),
            "force": pd.read_csv(tr["force"], sep="\t"),
            "force_direction": brace_force_direction(X, labels, source=str(tr["markers"])),
        })
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TooFewStridesWarning)  # the counts table carries the verdict
        response, counts, series = subject_onset_response(
            inputs, onset_ms, rate_hz, window_before_s, window_after_s, initial_state_span_s, whisker, max_fraction,
            min_strides, source=f"{subject}, onset {onset_ms} ms",
        )
    write_tsv(response, response_out)
    write_tsv(counts, counts_out)
    total = counts[counts["trial"] == "total"].iloc[0]
    n_kept = int(total["n_kept"])
    if n_kept < min_strides:
        rows = status_rows(subject, onset_ms, "failed",
                           f"{n_kept} valid perturbed stride(s), fewer than {min_strides}: not fitted", n_kept, truth)
        write_tsv(rows, fit_out)
        write_tsv(pd.DataFrame(columns=["time_s"]), curves_out)
        return rows
    params = SegmentParameters.from_tsv(segments_tsv)
    window = prepare_window(
        series["time_s"], series["q_unperturbed"], series["q_perturbed"], params, 0.0,
        force_unperturbed_n=series["force_unperturbed_n"], force_perturbed_n=series["force_perturbed_n"],
        pelvis_angle_unperturbed_rad=series["pelvis_angle_unperturbed_rad"],
        pelvis_angle_perturbed_rad=series["pelvis_angle_perturbed_rad"],
        window_before_s=window_before_s, window_after_s=window_after_s, n_substeps=n_substeps,
        initial_state_span_s=initial_state_span_s, initial_state_degree=initial_state_degree,
    )
    lower = np.array([stiffness_bounds[0], damping_bounds[0]] * 3, float)
    upper = np.array([stiffness_bounds[1], damping_bounds[1]] * 3, float)
    fit = identify_impedance(window, n_starts=n_starts, seed=seed, lower=lower, upper=upper, tolerance=tolerance,
                             merge_tolerance=merge_tolerance)
    used, n_null, note = "white", 0, ""
    if noise_model == "null_pairs":
        loaded = {i["name"]: i for i in inputs}
        pool = [loaded.get(str(t.get("name")), t) for t in null_trials] or inputs
        null = null_pair_windows(
            pool, onset_ms, rate_hz, window_before_s, window_after_s, initial_state_span_s,
            whisker, max_fraction, source=subject,
        )
        n_null = null["n_pairs"]
        if n_null >= max(int(min_null_pairs), int(null_pair_components) + 2):
            errors = null_pair_errors(window, fit.estimate, null)
            weight = nuisance_projection(errors, null_pair_components)
            cov = np.cov(errors, rowvar=False) / n_kept
            fit = identify_impedance(replace(window, noise_cov=cov, residual_weight=weight), n_starts=n_starts,
                                     seed=seed, lower=lower, upper=upper, tolerance=tolerance,
                                     merge_tolerance=merge_tolerance, extra_starts=fit.estimate)
            used = "null_pairs"
        else:
            note = (f"white-noise fit: {n_null} null pair(s), fewer than min_null_pairs = {min_null_pairs}; "
                    "the CI ignore the stride-to-stride deviation")
    rows = impedance_rows(fit, subject, onset_ms, n_kept, truth, (stiffness_bounds[0], damping_bounds[0]),
                          (stiffness_bounds[1], damping_bounds[1]), max_ci_fraction, used, n_null, note)
    write_tsv(rows, fit_out)
    fit_frame = pd.DataFrame({"time_s": fit.time_s, **{f"{j}_measured_rad": fit.measured[:, i] for i, j in enumerate(JOINTS)},
                              **{f"{j}_model_rad": fit.model[:, i] for i, j in enumerate(JOINTS)}})
    write_tsv(fit_frame, curves_out)
    return rows


#: Joint impedance in the literature (relaxed conditions), DESIGN.md section 5: (source, joint, K range, D range).
LITERATURE = (
    ("force perturbation, static", "hip", (50.0, 60.0), (7.0, 9.0)),
    ("force perturbation, static", "knee", (15.0, 20.0), (1.0, 2.0)),
    ("position perturbation, static", "hip", (75.0, 318.0), (2.0, 21.0)),
    ("position perturbation, static", "knee", (36.0, 75.0), (1.8, 2.2)),
    ("position perturbation, imposed motion", "knee", (25.0, 30.0), (None, None)),
    ("the study: swing phase, across-subject mean over onsets", "hip", (34.0, 66.0), (1.9, 4.6)),
    ("the study: swing phase, across-subject mean over onsets", "knee", (0.0, 3.5), (0.02, 0.14)),
)


def impedance_summary(table: pd.DataFrame, k_tolerance=(0.10, 2.0), d_tolerance=(0.15, 0.05)) -> pd.DataFrame:
    """Across-subject summary per joint and onset: mean, SD, min, max of K and D over subjects (fitted rows only).

    Columns ``joint, onset_ms, n_subjects, K_mean, K_sd, K_min, K_max, D_mean, ..., vaf_pct_mean``; where
    the truth is known also ``K_error_mean``, ``K_max_abs_error``, ``K_within_tolerance`` (fraction of
    subjects within ``max(rel * |truth|, abs)``) and the same for D.
    """
    fitted = table[table["status"].isin(["ok", "not_identifiable"])]
    rows = []
    for (joint, onset), g in fitted.groupby(["joint", "onset_ms"], sort=False):
        row = {"joint": joint, "onset_ms": int(onset), "n_subjects": g["subject"].nunique()}
        for p in ("K", "D"):
            row.update({f"{p}_mean": g[p].mean(), f"{p}_sd": g[p].std(ddof=1), f"{p}_min": g[p].min(),
                        f"{p}_max": g[p].max()})
        row["vaf_pct_mean"] = g["vaf_pct"].mean()
        known = g[g["K_true"].notna()]
        if len(known):
            for p, (rel, ab) in (("K", k_tolerance), ("D", d_tolerance)):
                err = known[f"{p}_error"]
                tol = np.maximum(rel * known[f"{p}_true"].abs(), ab)
                row.update({f"{p}_error_mean": err.mean(), f"{p}_max_abs_error": err.abs().max(),
                            f"{p}_within_tolerance": float((err.abs() <= tol).mean())})
        rows.append(row)
    order = {j: i for i, j in enumerate(JOINTS)}
    out = pd.DataFrame(rows, columns=None if rows else ["joint", "onset_ms", "n_subjects"])
    if len(out):
        out = out.sort_values(["joint", "onset_ms"], key=lambda c: c.map(order) if c.name == "joint" else c,
                              kind="stable", ignore_index=True)
    return out


def literature_table(summary: pd.DataFrame) -> pd.DataFrame:
    """DESIGN.md section 5's literature values with our row added: range over onsets of the across-subject mean."""
    rows = [{"source": s, "joint": j, "K_low": k[0], "K_high": k[1], "D_low": d[0], "D_high": d[1]}
            for s, j, k, d in LITERATURE]
    for joint in ("hip", "knee"):
        if "joint" not in summary.columns:  # nothing fitted
            break
        g = summary[summary["joint"] == joint]
        if len(g):
            rows.append({"source": "this pipeline: swing phase, across-subject mean over onsets", "joint": joint,
                         "K_low": g["K_mean"].min(), "K_high": g["K_mean"].max(),
                         "D_low": g["D_mean"].min(), "D_high": g["D_mean"].max()})
    return pd.DataFrame(rows)
