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
]

#: Columns of ``results/impedance/{subject}/{onset}.tsv`` and ``results/tables/impedance.tsv``.
IMPEDANCE_COLUMNS: tuple[str, ...] = (
    "subject", "onset_ms", "joint", "K", "D", "K_ci95_low", "K_ci95_high", "D_ci95_low", "D_ci95_high",
    "vaf_pct", "n_strides", "K_true", "D_true", "K_error", "D_error", "cost_rad2", "status", "reason",
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
                   lower=(0.0, 0.0), upper=(200.0, 10.0), max_ci_fraction: float = 0.5) -> pd.DataFrame:
    """One row per joint from an :class:`~loper_analysis.identification.ImpedanceFit` (columns :data:`IMPEDANCE_COLUMNS`).

    ``truth``: ``{joint: {"K": .., "D": ..}}`` of a synthetic subject (errors
    = estimate - truth), None for a recorded one.
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
    """
    import warnings

    from .dynamics import SegmentParameters
    from .gait import TooFewStridesWarning
    from .identification import identify_impedance, prepare_window
    from .io.tables import read_markers
    from .processing import write_tsv
    from .responses import subject_onset_response

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
    rows = impedance_rows(fit, subject, onset_ms, n_kept, truth, (stiffness_bounds[0], damping_bounds[0]),
                          (stiffness_bounds[1], damping_bounds[1]), max_ci_fraction)
    write_tsv(rows, fit_out)
    fit_frame = pd.DataFrame({"time_s": fit.time_s, **{f"{j}_measured_rad": fit.measured[:, i] for i, j in enumerate(JOINTS)},
                              **{f"{j}_model_rad": fit.model[:, i] for i, j in enumerate(JOINTS)}})
    write_tsv(fit_frame, curves_out)
    return rows
