"""The rules that read each key of the ``ik`` section: ``tests/test_config_readers.py`` changes each key in turn
and asserts that exactly these rules would rerun."""

READERS = {
    "ik.ik_tasks": "ik",
    "ik.default_marker_weight": "ik",
    "ik.marker_weights": "ik",
    "ik.coordinate_tasks": "ik",
    "ik.tree_step_tolerance": "ik model_scaled",
    "ik.opensim_accuracy": "ik model_scaled",
    "ik.ik_solver": "ik model_scaled",
    "ik.max_marker_rms_m": "ik",
    "ik.warn_marker_rms_m": "ik",
    "ik.max_rms_fraction": "ik",
    "ik.geometry_warn_change": "ik",
    "ik.geometry_stop_change": "ik",
    "ik.ik_chunks": "ik ik_chunk ik_join",
    "ik.coordinate_map": "dynamics ik model_scaled",
}
