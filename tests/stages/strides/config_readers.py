"""The rules that read each key of the ``strides`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "strides.n_points": "dynamics strides",
    "strides.iqr_whisker": "impedance_fit planning strides",
    "strides.max_outlier_fraction": "impedance_fit planning strides",
    "strides.min_valid_strides": "impedance_fit planning strides strides_summary transparency",
}
