"""The rules that read each key of the ``synthetic`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "synthetic.walking_duration_s": "front_page synthetic_lab",
    "synthetic.static_duration_s": "synthetic_lab",
    "synthetic.variability": "front_page synthetic_lab",
    "synthetic.timing_cv": "synthetic_lab",
    "synthetic.amplitude_cv": "synthetic_lab",
    "synthetic.study_variability": "synthetic_lab",
    "synthetic.device_adaptation": "synthetic_lab",
    "synthetic.marker_noise_sd_m": "synthetic_lab",
    "synthetic.marker_gaps_per_trial": "synthetic_lab",
    "synthetic.max_gap_frames": "synthetic_lab",
    "synthetic.grf_noise_sd_n": "synthetic_lab",
    "synthetic.clock_offset_s": "synthetic_lab",
    "synthetic.clock_drift_ppm": "synthetic_lab",
    "synthetic.pulse_force_n": "front_page synthetic_lab",
    "synthetic.pulse_duration_s": "front_page synthetic_lab",
    "synthetic.perturb_every_strides": "synthetic_lab",
    "synthetic.shank_pulse_force_n": "synthetic_lab",
    "synthetic.between_subject_cv": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.50": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.175": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.300": "synthetic_truth",
    "synthetic.damping_nms_per_rad.50": "synthetic_truth",
    "synthetic.damping_nms_per_rad.175": "synthetic_truth",
    "synthetic.damping_nms_per_rad.300": "synthetic_truth",
}
