"""The rules that read each key of the ``validation`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "validation.subject_height_m": "validation_segments",
    "validation.subject_mass_kg": "validation_segments",
    "validation.attachment_fraction_of_thigh": "validation_segments",
    "validation.stiffness_levels_nm_per_rad": "validation_chunk",
    "validation.damping_levels_nms_per_rad": "validation_chunk",
    "validation.sample_rate_hz": "validation_chunk",
    "validation.swing_duration_s": "validation_chunk",
    "validation.onset_s": "validation_chunk",
    "validation.pulse_force_n": "validation_chunk",
    "validation.pulse_duration_s": "validation_chunk",
    "validation.pulse_rise_time_s": "validation_chunk",
    "validation.pulse_overshoot_pct": "validation_chunk",
    "validation.force_rate_hz": "validation_chunk",
    "validation.force_direction_deg": "validation_chunk",
    "validation.noise_peak_to_peak": "validation_chunk",
    "validation.truth_substeps": "validation_chunk",
    "validation.n_chunks": "validation_chunk validation_gather",
}
