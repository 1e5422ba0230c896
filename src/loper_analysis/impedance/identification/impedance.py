"""Impedance per subject and onset: the fit of the mean response and its table rows (aggregated across subjects
by :mod:`loper_analysis.impedance.identification.across_subjects`).

:func:`fit_onset` runs the response analysis (:mod:`loper_analysis.impedance.responses`)
and the identification (:mod:`loper_analysis.impedance.identification`) for one
subject and onset, on the subject's segment table and the rod force along
the brace normal. A row per joint reports K, D, their 95 % confidence
intervals, the VAF, the number of strides, the truth of a synthetic subject
and a status (``docs/identification.md``):

* ``ok`` (also with an estimate on a lower bound of zero: no measurable K or D);
* ``not_identifiable``: K or D on its upper bound (or on a lower bound
  above zero), or its 95 % CI holds both 0 and the upper end of the joint's
  plausible range (``plausible_ranges``: the data cannot tell its size), or
  is at least as wide as that range (the reason names the parameter of
  another joint it trades off against), or spans more than
  ``max_ci_fraction`` of its bound range, or the joint's model response is
  smaller than its residual (``min_response_to_residual``);
* ``missing``: no trial of that onset;
* ``failed``: too few strides (the reason names ``impedance.window_after_s``
  when strides were too short for the window), the optimiser did not
  converge, or the joint's VAF is below ``min_vaf_pct``; ``reason`` says why.

The rules of a fitted row are :func:`loper_analysis.impedance.identification.joint_status`.
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, parameter_column
from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.impedance.identification import (
    AT_BOUND_FRACTION,
    DAMPING_BOUNDS_NMS_PER_RAD,
    DEFAULT_PLAUSIBLE_RANGES,
    FIT_TOLERANCE,
    INITIAL_STATE_DEGREE,
    MAX_CI_FRACTION,
    MERGE_TOLERANCE,
    MIN_NULL_PAIRS,
    MIN_RESPONSE_TO_RESIDUAL,
    MIN_VAF_PCT,
    N_STARTS,
    N_SUBSTEPS,
    NULL_PAIR_COMPONENTS,
    STIFFNESS_BOUNDS_NM_PER_RAD,
    FitBounds,
    ImpedanceFit,
    PreparedWindow,
    check_interval_scatter,
    data_finding_inputs,
    identify_impedance,
    joint_status,
    refit_with_null_pairs,
    strongest_coupling,
)
from loper_analysis.impedance.identification.coupling_rows import COUPLING_COLUMNS, coupling_rows
from loper_analysis.impedance.identification.jackknife import onset_jackknife, widen_to_pair_scatter
from loper_analysis.impedance.identification.onset_fit import (
    fit_curves,
    fit_null_pairs,
    force_table,
    mean_response_window,
)
from loper_analysis.impedance.identification.pair_averaging import averaging_corrected_fit, pair_windows
from loper_analysis.impedance.identification.parameters import check_couplings
from loper_analysis.impedance.responses import (
    MAX_TRIAL_DEVIATION_RATIO,
    ResponseSettings,
    subject_onset_response,
)
from loper_analysis.impedance.responses.rod_directions import brace_force_direction, shank_force_direction
from loper_analysis.swing_leg.dynamics import SegmentParameters
from loper_analysis.swing_leg.rods import ShankRod

__all__ = [
    "IMPEDANCE_COLUMNS",
    "NOISE_MODELS",
    "IdentificationSettings",
    "OnsetFit",
    "impedance_rows",
    "status_rows",
    "too_short_reason",
    "fit_onset",
]

log = logging.getLogger(__name__)

_K, _D = parameter_column("K"), parameter_column("D")

#: Columns of ``results/impedance/{subject}/{onset}.tsv`` and ``results/impedance/impedance.tsv``.
IMPEDANCE_COLUMNS: tuple[str, ...] = (
    "subject",
    "onset_ms",
    "joint",
    _K,
    _D,
    parameter_column("K", "ci95_low"),
    parameter_column("K", "ci95_high"),
    parameter_column("D", "ci95_low"),
    parameter_column("D", "ci95_high"),
    parameter_column("K", "se"),
    parameter_column("D", "se"),
    "ci_dof",
    "vaf_pct",
    "n_strides",
    parameter_column("K", "true"),
    parameter_column("D", "true"),
    parameter_column("K", "error"),
    parameter_column("D", "error"),
    "sum_sq_error_rad2",
    "n_starts",
    "n_starts_at_best",
    "noise_model",
    "n_null_pairs",
    "K_coupled_with",
    "K_coupling_correlation",
    "D_coupled_with",
    "D_coupling_correlation",
    "status",
    "reason",
)
#: How the fit weights its prediction errors: the study's least squares, or with the null pairs' deviation.
NOISE_MODELS: tuple[str, ...] = ("null_pairs", "white")


@dataclass(frozen=True)
class IdentificationSettings(FitBounds):
    """How K and D are fitted and judged (config ``identification``; bounds in N·m/rad and N·m·s/rad).

    ``min_vaf_pct``: a joint whose VAF (%) is below it is ``failed``;
    ``plausible_ranges``: ``{joint: {"stiffness_nm_per_rad": [low, high],
    "damping_nms_per_rad": [low, high]}}`` for the identifiability rule (None:
    :data:`~loper_analysis.impedance.identification.DEFAULT_PLAUSIBLE_RANGES`);
    ``max_null_trial_ratio``: a trial whose null pairs deviate more than this
    multiple of the other trials' is left out of the null pairs (None: never);
    ``interval_scatter``: with the ``null_pairs`` noise model, whose scatter
    gives the 95 % intervals: ``perturbed_pairs`` (the averaged pairs
    themselves), ``null_pairs`` or ``cross_validated_null_pairs`` (each null
    pair judged by a projection made without it;
    :func:`loper_analysis.impedance.identification.refit_with_null_pairs`).
    ``averaging_correction``: fit the mean response less what averaging the pairs does to the model's
    response (:mod:`loper_analysis.impedance.identification.pair_averaging`). ``couplings``: inter-joint
    (bi-articular) stiffnesses fitted beside K and D (names of :data:`~loper_analysis.constants.COUPLINGS`, e.g.
    ``("hip_knee",)``; :func:`~loper_analysis.impedance.identification.coupling_rows.coupling_rows` reports them).
    """

    noise_model: str = "null_pairs"
    interval_scatter: str = "cross_validated_null_pairs"
    null_pair_components: int = NULL_PAIR_COMPONENTS
    min_null_pairs: int = MIN_NULL_PAIRS
    initial_state_degree: int = INITIAL_STATE_DEGREE
    n_starts: int = N_STARTS
    n_substeps: int = N_SUBSTEPS
    tolerance: float = FIT_TOLERANCE
    merge_tolerance: float = MERGE_TOLERANCE
    stiffness_bounds_nm_per_rad: tuple[float, float] = STIFFNESS_BOUNDS_NM_PER_RAD
    damping_bounds_nms_per_rad: tuple[float, float] = DAMPING_BOUNDS_NMS_PER_RAD
    max_ci_fraction: float = MAX_CI_FRACTION
    plausible_ranges: Mapping | None = None
    min_vaf_pct: float = MIN_VAF_PCT
    max_null_trial_ratio: float | None = MAX_TRIAL_DEVIATION_RATIO
    seed: int = 0
    averaging_correction: bool = True
    couplings: tuple[str, ...] = ()

    def __post_init__(self):
        if self.noise_model not in NOISE_MODELS:
            raise LoperInputError(f"impedance.noise_model must be 'null_pairs' or 'white', got {self.noise_model!r}")
        check_interval_scatter(self.interval_scatter)
        try:
            object.__setattr__(self, "couplings", check_couplings(self.couplings))
        except LoperInputError as exc:
            raise LoperInputError(f"impedance.couplings: {exc}") from None

    def fit_options(self) -> dict:
        """Keyword arguments of :func:`loper_analysis.impedance.identification.identify_impedance`."""
        return dict(
            n_starts=self.n_starts,
            seed=self.seed,
            lower=self.lower,
            upper=self.upper,
            tolerance=self.tolerance,
            merge_tolerance=self.merge_tolerance,
        )


@dataclass
class OnsetFit:
    """Everything :func:`fit_onset` finds for one subject and onset.

    ``response``: the mean response (:func:`loper_analysis.impedance.responses.subject_onset_response`,
    empty when no trial); ``counts``: perturbed strides per trial and their
    fate; ``rows``: one row per joint (:data:`IMPEDANCE_COLUMNS`);
    ``curves``: the measured and model responses of the fit (``time_s``,
    ``{joint}_measured_rad``, ``{joint}_model_rad``; only ``time_s`` when
    nothing was fitted); ``force``: the mean rod forces the model was given
    (:func:`force_table`; only ``time_s`` when nothing was fitted); ``couplings``: one row per inter-joint
    coupling fitted (``impedance.couplings``; columns
    :data:`~loper_analysis.impedance.identification.coupling_rows.COUPLING_COLUMNS`, no row without one or
    without a fit).
    """

    response: pd.DataFrame
    counts: pd.DataFrame
    rows: pd.DataFrame
    curves: pd.DataFrame
    force: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=["time_s"]))
    couplings: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=list(COUPLING_COLUMNS)))


def _truth_columns(row: dict, truth: Mapping | None, joint: str) -> None:
    if truth is not None:
        row[parameter_column("K", "true")] = truth[joint]["K"]
        row[parameter_column("D", "true")] = truth[joint]["D"]


def _plausible_range(plausible_ranges: Mapping | None, joint: str):
    """((K low, K high), (D low, D high)) of ``joint`` from config-shaped ``plausible_ranges`` (None: the default)."""
    if plausible_ranges is None:
        return DEFAULT_PLAUSIBLE_RANGES[joint]
    entry = plausible_ranges.get(joint)
    if not isinstance(entry, Mapping) or not {"stiffness_nm_per_rad", "damping_nms_per_rad"} <= set(entry):
        raise LoperInputError(
            f"impedance.plausible_ranges: the {joint} needs stiffness_nm_per_rad and "
            f"damping_nms_per_rad ([low, high] each), got {entry!r}"
        )
    return (tuple(entry["stiffness_nm_per_rad"]), tuple(entry["damping_nms_per_rad"]))


def impedance_rows(
    fit: ImpedanceFit,
    subject: str,
    onset_ms: int,
    n_strides: int,
    truth: Mapping | None = None,
    *,
    lower=(STIFFNESS_BOUNDS_NM_PER_RAD[0], DAMPING_BOUNDS_NMS_PER_RAD[0]),
    upper=(STIFFNESS_BOUNDS_NM_PER_RAD[1], DAMPING_BOUNDS_NMS_PER_RAD[1]),
    max_ci_fraction: float = MAX_CI_FRACTION,
    noise_model: str = "white",
    n_null_pairs: int = 0,
    note: str = "",
    min_vaf_pct: float = MIN_VAF_PCT,
    at_bound_fraction: float = AT_BOUND_FRACTION,
    plausible_ranges: Mapping | None = None,
    min_response_to_residual: float = MIN_RESPONSE_TO_RESIDUAL,
    interval_notes: Mapping[str, str] | None = None,
) -> pd.DataFrame:
    """One row per joint from an :class:`~loper_analysis.impedance.identification.ImpedanceFit` (columns
    :data:`IMPEDANCE_COLUMNS`).

    ``truth``: ``{joint: {"K": .., "D": ..}}`` of a synthetic subject (errors
    = estimate - truth), None for a recorded one. ``lower``, ``upper``: the
    bounds of (K, D). ``noise_model`` (``white`` | ``null_pairs``) and
    ``n_null_pairs`` say how the fit weighted its errors; ``note`` is appended
    to every row's reason. Status and reason per joint:
    :func:`loper_analysis.impedance.identification.joint_status` with the joint's
    entry of ``plausible_ranges`` (``{joint: {"stiffness_nm_per_rad": [low,
    high], "damping_nms_per_rad": [low, high]}}``; None:
    :data:`~loper_analysis.impedance.identification.DEFAULT_PLAUSIBLE_RANGES`),
    ``max_ci_fraction``, ``min_vaf_pct``, ``at_bound_fraction`` and ``min_response_to_residual``.
    ``interval_notes``: per parameter (``K_ankle``) a text its joint's reason carries, e.g. that its interval
    comes from the perturbed pairs' scatter
    (:func:`~loper_analysis.impedance.identification.jackknife.widen_to_pair_scatter`).
    """
    rows = []
    for j, joint in enumerate(JOINTS):
        k, d = 2 * j, 2 * j + 1
        row = {
            "subject": subject,
            "onset_ms": int(onset_ms),
            "joint": joint,
            _K: fit.estimate[k],
            _D: fit.estimate[d],
            parameter_column("K", "ci95_low"): fit.ci95_low[k],
            parameter_column("K", "ci95_high"): fit.ci95_high[k],
            parameter_column("D", "ci95_low"): fit.ci95_low[d],
            parameter_column("D", "ci95_high"): fit.ci95_high[d],
            parameter_column("K", "se"): fit.sd[k],
            parameter_column("D", "se"): fit.sd[d],
            "ci_dof": int(fit.ci_dof),
            "vaf_pct": fit.vaf_pct[j],
            "n_strides": int(n_strides),
            "sum_sq_error_rad2": fit.sum_sq_error_rad2,
            "n_starts": fit.n_starts,
            "n_starts_at_best": fit.n_starts_at_best,
            "noise_model": noise_model,
            "n_null_pairs": int(n_null_pairs),
        }
        _truth_columns(row, truth, joint)
        if truth is not None:
            row[parameter_column("K", "error")] = row[_K] - truth[joint]["K"]
            row[parameter_column("D", "error")] = row[_D] - truth[joint]["D"]
        coupling = strongest_coupling(fit.correlation, joint, fit.parameters)
        for p, c in zip(("K", "D"), coupling):
            row[f"{p}_coupled_with"], row[f"{p}_coupling_correlation"] = c if c is not None else ("", np.nan)
        status, reason = joint_status(
            joint,
            fit.estimate[[k, d]],
            fit.ci95_low[[k, d]],
            fit.ci95_high[[k, d]],
            fit.vaf_pct[j],
            lower,
            upper,
            success=fit.success,
            message=fit.message,
            plausible_range=_plausible_range(plausible_ranges, joint),
            max_ci_fraction=max_ci_fraction,
            min_vaf_pct=min_vaf_pct,
            at_bound_fraction=at_bound_fraction,
            coupling=coupling,
            **data_finding_inputs(fit, j),
            min_response_to_residual=min_response_to_residual,
        )
        own = [(interval_notes or {}).get(f"{p}_{joint}", "") for p in ("K", "D")]
        row.update(status=status, reason="; ".join(r for r in (reason, *own, note) if r))
        rows.append(row)
    return pd.DataFrame(rows).reindex(columns=IMPEDANCE_COLUMNS)


def status_rows(
    subject: str, onset_ms: int, status: str, reason: str, n_strides: int = 0, truth: Mapping | None = None
) -> pd.DataFrame:
    """Rows without a fit (``missing`` or ``failed``), one per joint, estimates empty."""
    rows = []
    for joint in JOINTS:
        row = {
            "subject": subject,
            "onset_ms": int(onset_ms),
            "joint": joint,
            "n_strides": int(n_strides),
            "status": status,
            "reason": reason,
        }
        _truth_columns(row, truth, joint)
        rows.append(row)
    return pd.DataFrame(rows).reindex(columns=IMPEDANCE_COLUMNS)


def too_short_reason(
    n_short: int, n_perturbed: int, onset_ms: float, window_after_s: float, longest_after_onset_s: float
) -> str:
    """Why perturbed strides were dropped as too short, naming ``impedance.window_after_s`` and its value.

    ``longest_after_onset_s``: the most swing time (s) any perturbed stride leaves after its onset,
    the longest window that keeps a stride.
    """
    text = (
        f"{n_short} of {n_perturbed} perturbed stride(s) too short for the fit window: their swing ends "
        f"before onset {onset_ms:g} ms + impedance.window_after_s = {window_after_s:g} s"
    )
    if np.isfinite(longest_after_onset_s):
        text += f" (the longest swing leaves {max(longest_after_onset_s, 0.0):.3g} s after the onset)"
    return text


def _no_curves() -> pd.DataFrame:
    return pd.DataFrame(columns=["time_s"])


def fit_onset(
    trials: Sequence[Mapping],
    params: SegmentParameters | None,
    onset_ms: int,
    subject: str,
    truth: Mapping | None = None,
    null_trials: Sequence[Mapping] = (),
    response: ResponseSettings = ResponseSettings(),
    identification: IdentificationSettings = IdentificationSettings(),
    *,
    shank_rod: ShankRod | None = None,
) -> OnsetFit:
    """Responses and the impedance fit of one subject at one onset.

    Parameters
    ----------
    trials : sequence of mapping
        One per trial of this onset: ``name``, ``angles``, ``strides`` and
        ``force`` (frames of the processing steps, see
        :mod:`loper_analysis.impedance.responses.inputs`), optionally ``force_native``
        (the load cell at the robot rate: ``time_s``, ``force_measured_n``;
        the fit then gets the force at that rate) and ``markers``: ``(time_s
        (n,), markers_m (n, n_markers, 3) in the model frame, labels)`` for
        the brace markers. No trial: every output says ``missing``.
    params : SegmentParameters
        The subject's segment table (not needed without trials).
    onset_ms : int
        Onset after toe-off (ms).
    subject : str
        Subject ID, written in the rows and quoted in messages.
    truth : mapping, optional
        ``{joint: {"K": .., "D": ..}}`` of a synthetic subject at this onset.
    null_trials : sequence of mapping
        ``name``, ``angles``, ``strides`` of the trials whose unperturbed
        strides give the null pairs (e.g. all the subject's walking trials
        with the device; the onset's own trials when empty). Used with
        ``impedance.noise_model`` ``null_pairs``: the white fit first,
        then :func:`loper_analysis.impedance.identification.refit_with_null_pairs`. A
        trial whose null pairs deviate more than
        ``impedance.max_null_trial_ratio`` times the other trials' is
        left out of them (:func:`loper_analysis.impedance.responses.deviant_trials`);
        the rows' reason names it. With ``response.counterfactual``
        ``conditional`` the null pairs are instead the onset's own unperturbed
        strides, each predicted from the others
        (:func:`loper_analysis.impedance.responses.conditional.conditional_null_pairs`).
    response, identification : settings
    shank_rod : ShankRod, optional
        Where a second rod just above the ankle pushes (:class:`~loper_analysis.swing_leg.rods.ShankRod`; None:
        the default place and push). Used when the trials' ``force`` (and ``force_native``) tables hold that rod's
        load cell, ``shank_force_measured_n``: the fit then takes both rods' forces, the shank rod's along the
        shank's normal (from the joint angles) turned by the rod's angle, at ``params``' shank length times
        the rod's attachment fraction. Trials must agree on whether they hold it.

    Returns
    -------
    OnsetFit
    """
    if not trials:
        counts = pd.DataFrame([{"trial": "total", "status": "missing", "reason": "no trial of this onset"}])
        rows = status_rows(subject, onset_ms, "missing", "no trial of this onset", truth=truth)
        return OnsetFit(pd.DataFrame(), counts, rows, _no_curves())
    inputs = [_response_input(tr, shank_rod) for tr in trials]
    two_rods = {np.shape(i["force_direction"])[1] == 4 for i in inputs}
    if len(two_rods) > 1:
        names = [str(i["name"]) for i in inputs if np.shape(i["force_direction"])[1] == 4]
        raise LoperInputError(
            f"{subject}, onset {onset_ms} ms: trial(s) {', '.join(names)} hold a second rod's load cell "
            "(shank_force_measured_n) and the others do not: one fit takes one design"
        )
    if two_rods == {True}:
        rod = ShankRod() if shank_rod is None else shank_rod
        params = params.replace(shank_attachment_m=rod.attachment_m(params.length_m[1]))
    mean, counts, series, r, fallback = _onset_response(inputs, onset_ms, subject, response, identification)
    total = counts[counts["trial"] == "total"].iloc[0]
    n_kept = int(total["n_kept"])
    if n_kept < r.min_strides:
        rows = status_rows(subject, onset_ms, "failed", _not_fitted_reason(counts, onset_ms, r), n_kept, truth)
        return OnsetFit(mean, counts, rows, _no_curves())
    ident = identification
    options = dict(
        window=r.window,
        n_substeps=ident.n_substeps,
        initial_state_degree=ident.initial_state_degree,
        couplings=ident.couplings,
    )
    window = mean_response_window(series, params, options)
    fit = identify_impedance(window, **ident.fit_options())
    averaging = np.zeros_like(window.measured)
    if ident.averaging_correction:
        windows = pair_windows(series["pairs"], params, **options)
        window, fit, averaging = averaging_corrected_fit(window, windows, fit, **ident.fit_options())
    used, n_null, note, widened = "white", 0, "", {}
    if ident.noise_model == "null_pairs":
        null = fit_null_pairs(inputs, null_trials, series, onset_ms, r, ident.max_null_trial_ratio, subject)
        fit, used, n_null, note, widened = _null_pair_interval_fit(
            window, fit, series["pairs"], null, n_kept, params, options, ident
        )
    note = "; ".join(filter(None, [fallback, note]))
    rows = impedance_rows(
        fit,
        subject,
        onset_ms,
        n_kept,
        truth,
        lower=(ident.stiffness_bounds_nm_per_rad[0], ident.damping_bounds_nms_per_rad[0]),
        upper=(ident.stiffness_bounds_nm_per_rad[1], ident.damping_bounds_nms_per_rad[1]),
        max_ci_fraction=ident.max_ci_fraction,
        noise_model=used,
        n_null_pairs=n_null,
        note=note,
        min_vaf_pct=ident.min_vaf_pct,
        plausible_ranges=ident.plausible_ranges,
        interval_notes=widened,
    )
    couplings = coupling_rows(fit, subject, onset_ms, n_kept, truth, note=note, interval_notes=widened)
    return OnsetFit(mean, counts, rows, fit_curves(fit, averaging), force_table(series), couplings)


def _null_pair_interval_fit(
    window: PreparedWindow,
    fit: ImpedanceFit,
    pairs: Mapping,
    null: Mapping,
    n_kept: int,
    params: SegmentParameters,
    options: Mapping,
    ident,
) -> tuple[ImpedanceFit, str, int, str, dict[str, str]]:
    """The refit of ``fit`` with the null pairs ``null``
    (:func:`~loper_analysis.impedance.identification.refit_with_null_pairs`, intervals from the scatter
    ``ident.interval_scatter`` names) and, when it took them, its intervals widened where the perturbed ``pairs``
    (the responses' per-pair series) scatter beyond them
    (:func:`~loper_analysis.impedance.identification.jackknife.widen_to_pair_scatter`).

    ``n_kept``: the perturbed pairs averaged; ``options``: the window keywords of the mean window; ``ident``: the
    identification settings. Returns the fit, the noise model used (``null_pairs`` or ``white``), the null pairs
    taken, the note (trials left out, why the white fit stands) and the widened parameters' texts.
    """
    refit = refit_with_null_pairs(
        window,
        fit,
        null,
        n_kept,
        n_components=ident.null_pair_components,
        min_null_pairs=ident.min_null_pairs,
        cross_validated=ident.interval_scatter == "cross_validated_null_pairs",
        perturbed_pairs=pairs if ident.interval_scatter == "perturbed_pairs" else None,
        **ident.fit_options(),
    )
    fit, widened = refit.fit, {}
    if refit.noise_model == "null_pairs":  # the perturbed pairs' own scatter where it exceeds the interval's
        jackknife = onset_jackknife(window, fit.estimate, pairs, null, params, options, ident)
        fit, widened = widen_to_pair_scatter(fit, jackknife, ident.lower, ident.upper)
    note = "; ".join([*null["trials_left_out"].values(), *([refit.note] if refit.note else [])])
    return fit, refit.noise_model, refit.n_null_pairs, note, widened


def _response_input(trial: Mapping, shank_rod: ShankRod | None = None) -> dict:
    """One trial as :func:`loper_analysis.impedance.responses.subject_onset_response` takes it: its frames, with
    the rods' force direction (n, 2) from the brace markers of ``trial["markers"]`` (:func:`brace_force_direction`);
    (n, 4) when its force table holds a second rod's load cell, that rod's direction after the thigh rod's
    (:func:`shank_force_direction`)."""
    t, X, labels = trial["markers"]
    angles = trial["angles"]
    if len(t) != len(angles) or not np.allclose(t, angles["time_s"].to_numpy(), atol=1e-6):
        raise LoperInputError(f"{trial['name']}: marker frames differ from the joint angles' frames")
    direction = brace_force_direction(X, labels, source=str(trial["name"]))
    if "shank_force_measured_n" in trial["force"].columns:
        rod = ShankRod() if shank_rod is None else shank_rod
        direction = np.concatenate([direction, shank_force_direction(angles, rod, str(trial["name"]))], axis=1)
    return {
        "name": trial["name"],
        "angles": angles,
        "strides": trial["strides"],
        "force": trial["force"],
        "force_direction": direction,
        "force_native": trial.get("force_native"),
    }


def _onset_response(
    inputs: Sequence[Mapping],
    onset_ms: int,
    subject: str,
    response: ResponseSettings,
    identification: IdentificationSettings,
) -> tuple[pd.DataFrame, pd.DataFrame, dict, ResponseSettings, str]:
    """The mean response, counts and series of the onset
    (:func:`loper_analysis.impedance.responses.subject_onset_response`),
    the response settings they were made with and why those differ from ``response`` ("" when they do not).

    With the conditional counterfactual and fewer unperturbed strides than ``impedance.min_null_pairs``,
    the matched stride instead (a warning in the log).
    """
    r, fallback = response, ""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TooFewStridesWarning)  # the counts table carries the verdict
        mean, counts, series = subject_onset_response(inputs, onset_ms, r, source=f"{subject}, onset {onset_ms} ms")
        n_candidates = int(series.get("null_pairs", {}).get("n_pairs", 0))
        if r.counterfactual == "conditional" and n_candidates < identification.min_null_pairs:
            # too few unperturbed strides in the onset's trials to judge the prediction: the study's matched stride
            fallback = (
                f"matched stride instead of the conditional counterfactual: {n_candidates} unperturbed stride(s) of "
                f"the onset's trials, fewer than impedance.min_null_pairs = {identification.min_null_pairs}"
            )
            log.warning("%s, onset %s ms: %s", subject, onset_ms, fallback)
            r = replace(r, counterfactual="matched_stride")
            mean, counts, series = subject_onset_response(inputs, onset_ms, r, source=f"{subject}, onset {onset_ms} ms")
    return mean, counts, series, r, fallback


def _not_fitted_reason(counts: pd.DataFrame, onset_ms: int, response: ResponseSettings) -> str:
    """Why an onset with fewer kept pairs than ``response.min_strides`` (the counts' ``total`` row) is not fitted,
    naming the strides too short for the window."""
    total = counts[counts["trial"] == "total"].iloc[0]
    n_kept = int(total["n_kept"])
    reason = f"{n_kept} valid perturbed stride(s), fewer than {response.min_strides}: not fitted"
    if int(total["n_too_short"]):
        reason += "; " + too_short_reason(
            int(total["n_too_short"]),
            int(total["n_perturbed"]),
            onset_ms,
            response.window.after_s,
            counts.attrs["longest_swing_after_onset_s"],
        )
    return reason
