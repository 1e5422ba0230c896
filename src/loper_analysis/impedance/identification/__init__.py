"""Joint impedance (K, D per joint) from a perturbed and an unperturbed stride (method: ``docs/identification.md``).

1. The unperturbed measured coordinates ``q_u`` (cubic spline through the
   samples) are the reference; ``u_ff`` is their inverse dynamics, which
   absorbs the minimal-impedance device force ``F_u``.
2. The perturbed model is driven by ``u_ff + u_fb + Ja(q)^T F_p - Ja(q_u)^T F_u``
   with the impedance feedback ``T = -K dtheta - D dtheta'`` about the
   unperturbed joint angles, from the measured state at window start. The
   *deviation* ``e = q_model - q_u`` is integrated (fixed-step RK4,
   ``n_substeps`` steps per sample): the study's "simulate perturbed and
   unperturbed and subtract", with the unperturbed simulation exact by
   construction, so no integration error of the unperturbed path leaks into
   the fit (:mod:`.window`).
3. Prediction error ``PE = (theta_p - theta_u)_measured - (theta_p - theta_u)_model``
   on hip, knee and ankle angles over the window (25 ms before to 250 ms
   after onset by default).
4. The cost ``sum (W PE)^2`` is minimised with K in [0, 200] N m/rad, D in
   [0, 10] N m s/rad from random starts (:mod:`.fit`), with 95 % confidence
   intervals, the correlation matrix and the VAF per joint.

Beyond the study, :mod:`.null_pairs` weights the prediction error by the
stride-to-stride deviation that null pairs show, and :mod:`.status` judges
each joint's fit (convergence, VAF floor, bounds, the information in the
intervals), whose ends :mod:`.intervals` forms. :mod:`.impedance` fits each subject's
mean response per onset, :mod:`.across_subjects` aggregates the fits; :mod:`.validation` is the
synthetic validation study of the whole identification.
"""

from loper_analysis.impedance.identification.fit import (
    AT_BEST_RELATIVE,
    DAMPING_BOUNDS_NMS_PER_RAD,
    DEFAULT_LOWER,
    DEFAULT_UPPER,
    FIT_TOLERANCE,
    MERGE_TOLERANCE,
    N_STARTS,
    STIFFNESS_BOUNDS_NM_PER_RAD,
    FitBounds,
    ImpedanceFit,
    identify_impedance,
    parameter_bounds,
    response_jacobian,
    starts_at_best,
    variance_accounted_for,
)
from loper_analysis.impedance.identification.intervals import CI_LEVEL, bounded_interval, t_quantile
from loper_analysis.impedance.identification.jackknife import PAIR_SCATTER_LEVEL
from loper_analysis.impedance.identification.null_pairs import (
    INTERVAL_SCATTERS,
    MIN_NULL_PAIRS,
    NULL_PAIR_COMPONENTS,
    NullPairFit,
    check_interval_scatter,
    cross_validated_covariance,
    nuisance_projection,
    null_pair_errors,
    refit_with_null_pairs,
)
from loper_analysis.impedance.identification.status import (
    AT_BOUND_FRACTION,
    COUPLING_CORRELATION,
    DEFAULT_PLAUSIBLE_RANGES,
    MAX_CI_FRACTION,
    MIN_RESPONSE_TO_RESIDUAL,
    MIN_VAF_PCT,
    check_plausible_range,
    data_finding_inputs,
    joint_status,
    response_and_residual_rms,
    strongest_coupling,
)
from loper_analysis.impedance.identification.window import (
    INITIAL_STATE_DEGREE,
    INITIAL_STATE_SPAN_S,
    N_SUBSTEPS,
    WINDOW_AFTER_S,
    WINDOW_BEFORE_S,
    PreparedWindow,
    per_step,
    prediction_error,
    prepare_window,
    simulate_deviation,
    simulate_response,
    stage_force_means,
    stage_times_s,
    step_stage_forces,
    window_options,
)

__all__ = [
    "AT_BEST_RELATIVE",
    "DEFAULT_LOWER",
    "DEFAULT_UPPER",
    "STIFFNESS_BOUNDS_NM_PER_RAD",
    "DAMPING_BOUNDS_NMS_PER_RAD",
    "N_STARTS",
    "FIT_TOLERANCE",
    "MERGE_TOLERANCE",
    "WINDOW_BEFORE_S",
    "WINDOW_AFTER_S",
    "INITIAL_STATE_SPAN_S",
    "INITIAL_STATE_DEGREE",
    "N_SUBSTEPS",
    "NULL_PAIR_COMPONENTS",
    "MIN_NULL_PAIRS",
    "PreparedWindow",
    "ImpedanceFit",
    "parameter_bounds",
    "FitBounds",
    "NullPairFit",
    "INTERVAL_SCATTERS",
    "check_interval_scatter",
    "prepare_window",
    "window_options",
    "per_step",
    "stage_times_s",
    "stage_force_means",
    "step_stage_forces",
    "simulate_deviation",
    "simulate_response",
    "prediction_error",
    "identify_impedance",
    "starts_at_best",
    "variance_accounted_for",
    "response_jacobian",
    "null_pair_errors",
    "nuisance_projection",
    "refit_with_null_pairs",
    "cross_validated_covariance",
    "MIN_VAF_PCT",
    "MIN_RESPONSE_TO_RESIDUAL",
    "PAIR_SCATTER_LEVEL",
    "MAX_CI_FRACTION",
    "AT_BOUND_FRACTION",
    "joint_status",
    "data_finding_inputs",
    "response_and_residual_rms",
    "strongest_coupling",
    "COUPLING_CORRELATION",
    "DEFAULT_PLAUSIBLE_RANGES",
    "check_plausible_range",
    "CI_LEVEL",
    "t_quantile",
    "bounded_interval",
]
