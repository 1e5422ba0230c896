"""The rules that read each key of the ``impedance`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "impedance.window_before_s": "front_page impedance_fit planning validation_chunk",
    "impedance.window_after_s": "front_page impedance_fit planning validation_chunk",
    "impedance.stiffness_bounds_nm_per_rad": (
        "front_page impedance_fit impedance_summary planning synthetic_truth validation_chunk"
    ),
    "impedance.damping_bounds_nms_per_rad": (
        "front_page impedance_fit impedance_summary planning synthetic_truth validation_chunk"
    ),
    "impedance.n_starts": "front_page impedance_fit validation_chunk",
    "impedance.n_substeps": "impedance_fit planning validation_chunk",
    "impedance.tolerance": "impedance_fit validation_chunk",
    "impedance.merge_tolerance": "impedance_fit validation_chunk",
    "impedance.initial_state_span_s": "impedance_fit planning validation_chunk",
    "impedance.initial_state_degree": "impedance_fit planning validation_chunk",
    "impedance.min_vaf_pct": "impedance_fit",
    "impedance.max_null_trial_ratio": "impedance_fit planning",
    "impedance.plausible_ranges": "impedance_fit",
    "impedance.max_ci_fraction": "impedance_fit",
    "impedance.noise_model": "front_page impedance_fit",
    "impedance.counterfactual": "impedance_fit planning",
    "impedance.interval_scatter": "impedance_fit planning",
    "impedance.averaging_correction": "impedance_fit",
    "impedance.null_pair_components": "front_page impedance_fit planning",
    "impedance.min_null_pairs": "impedance_fit planning",
    "impedance.couplings": "impedance_couplings_table impedance_fit planning tables_markdown",
}
