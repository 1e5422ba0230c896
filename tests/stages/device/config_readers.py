"""The rules that read each key of the ``device`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "device.subject": "device_frf device_steps",
    "device.parameters": "device_frf device_log_from_mat device_steps device_trial planning synthetic_lab",
    "device.leg": "device_trial",
    "device.tests": "device_trial",
    "device.analysis.welch_window_samples": "device_frf",
    "device.analysis.welch_overlap_samples": "device_frf",
    "device.analysis.bandwidth_reference_band_hz": "device_summary",
    "device.analysis.step_before_s": "device_steps",
    "device.analysis.step_after_s": "device_steps",
    "device.analysis.steady_window_s": "device_steps",
    "device.mat_column_map": "device_log_from_mat",
    "device.shank_rod.attachment_fraction": "impedance_fit planning synthetic_lab",
    "device.shank_rod.direction_deg": "impedance_fit planning synthetic_lab",
}
