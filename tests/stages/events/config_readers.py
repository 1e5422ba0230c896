"""The rules that read each key of the ``events`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "events.grf_channels": "events events_loadcell",
    "events.sync_channel": "events_loadcell synthetic_lab",
    "events.threshold_on_n": "events events_loadcell",
    "events.threshold_off_n": "events events_loadcell",
    "events.min_stance_s": "events events_loadcell",
    "events.min_swing_s": "events events_loadcell",
    "events.foot_markers": "events events_loadcell",
    "events.plate_sides": "events events_loadcell",
    "events.grf_cutoff_hz": "events events_loadcell",
}
