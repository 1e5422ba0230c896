"""The rules that read each key of the ``model`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "model.static_duration_s": "model_generic model_scaled",
    "model.static_max_motion_rms_m": "model_scaled",
    "model.generic_model": "model_scaled",
    "model.scale_setup": "model_scaled",
    "model.segment_bodies": "model_scaled model_segments",
    "model.brace_attachment_fraction": "model_segments",
    "model.scale_factor_range": "model_scaled",
}
