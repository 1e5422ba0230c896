"""The rules that read each key of the ``study`` section and the config's top-level keys:
``tests/test_config_readers.py`` changes each key in turn and asserts that exactly these rules would rerun."""

READERS = {
    "raw_dir": (
        "all device_frf device_log_from_mat device_steps device_trial events events_loadcell grf "
        "impedance_fit markers model_scaled synthetic_lab synthetic_truth"
    ),
    "seed": "device_trial front_page impedance_fit synthetic_lab synthetic_truth validation_chunk",
    "study.static": "ik markers model_scaled synthetic_lab",
    "study.no_device": (
        "all dynamics_trials events events_loadcell front_page strides strides_summary synthetic_lab transparency"
    ),
    "study.device": "all dynamics_trials front_page impedance_fit planning strides_summary synthetic_lab transparency",
    "study.perturbation_onsets_ms": (
        "all dynamics_trials front_page impedance_figures impedance_fit impedance_table planning "
        "strides_summary synthetic_lab"
    ),
    "study.perturbation_repeats": "all dynamics_trials front_page impedance_fit planning strides_summary synthetic_lab",
    "study.perturbed_side": "front_page model_segments strides synthetic_lab transparency",
}
