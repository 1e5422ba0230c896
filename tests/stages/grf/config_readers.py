"""The rules that read each key of the ``grf`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "grf.loaded_threshold_n": "grf",
    "grf.resting_band_n": "events events_loadcell grf",
    "grf.max_resting_n": "events events_loadcell grf",
}
