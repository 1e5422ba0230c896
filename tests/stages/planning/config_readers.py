"""The rules that read each key of the ``planning`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "planning.pilot_subject": "planning",
    "planning.strides": "planning",
    "planning.pulse_force_n": "events_loadcell planning",
    "planning.pulse_duration_s": "planning",
    "planning.shank_pulse_force_n": "events_loadcell planning",
    "planning.targets": "planning",
}
