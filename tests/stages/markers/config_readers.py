"""The rules that read each key of the ``markers`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "markers.lab_to_model_rotation_deg": "events events_loadcell grf markers model_generic model_scaled synthetic_lab",
    "markers.walking_direction": "markers",
    "markers.min_travel_speed_m_per_s": "markers",
    "markers.max_gap_frames": "markers",
    "markers.extent_range_m": "markers",
    "markers.label_map": "events events_loadcell markers",
    "markers.trial_label_maps": "events events_loadcell markers",
    "markers.trial_spans_s": "markers",
    "markers.filter.cutoff_hz": "events_loadcell front_page markers planning",
    "markers.filter.order": "events events_loadcell front_page markers planning",
}
