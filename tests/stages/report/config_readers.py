"""The rules that read each key of the ``report`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "report.calibration": "front_page",
}
