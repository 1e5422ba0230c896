"""Each config key reruns exactly the rules that read it: every setting of ``config/config.yaml`` changed in turn,
and the rules whose params or files change (what Snakemake's params and input triggers rerun) compared with the
readers listed here. A setting that reran a rule not reading it would redo work (and, upstream, everything after
it); one that reran none would be a setting nothing reads."""

from __future__ import annotations

import copy
import fnmatch
import re
from pathlib import Path

import pytest
import yaml

from tests.rule_params import rule_signatures

ROOT = Path(__file__).resolve().parents[1]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
#: Settings that are mappings of names, changed as a whole (their entries are not keys of the config).
MAPPINGS = {
    "coordinate_map",
    "grf_channels",
    "foot_markers",
    "plate_sides",
    "trial_label_maps",
    "trial_spans_s",
    "label_map",
    "mat_column_map",
    "parameters",
    "leg",
    "tests",
    "plausible_ranges",
    "study_variability",
    "device_adaptation",
    "marker_weights",
    "coordinate_tasks",
    "segment_bodies",
    "targets",
}
#: The subject sheet is no setting: another sheet is another study.
NOT_SETTINGS = {"subjects"}
#: Changed values that need more than a nudge (names, files that exist, mappings, a value within its limits).
CHANGES = {
    "raw_dir": "lab/raw",
    "study.static": "static2",
    "study.no_device": "walk-free",
    "study.device": "walk-loper",
    "study.perturbation_onsets_ms": [50, 175],
    "impedance.max_ci_fraction": 0.45,
    "markers.label_map": {"LASI": "LASI"},
    "markers.trial_label_maps": {"walking": {"LASI": "LASI"}},
    "markers.trial_spans_s": {"S01/pert050-1": [1.0, 20.0]},
    "events.grf_cutoff_hz": 30.0,
    "events.sync_channel": "sync2",
    "planning.pilot_subject": "S02",
    "planning.targets": [{"joint": "hip", "parameter": "K", "percent": 10}],
    "ik.marker_weights": {"LASI": 2.0},
    "ik.coordinate_tasks": {"pelvis_tilt": {"weight": 1.0, "value": None}},
    "device.subject": "S02",
    "model.generic_model": "examples/gait2392/gait2392_simbody.osim",
    "model.scale_setup": "examples/gait2392/scale_setup.xml",
    "ik.ik_tasks": "examples/rajagopal2016/lower_body_ik_tasks.tsv",
    "model.segment_bodies": {"thigh": ["femur_{s}"], "shank": ["tibia_{s}"], "foot": ["calcn_{s}"]},
    "ik.coordinate_map": {"hip_left": {"coordinate": "hip_flexion_l", "sign": -1}},
    "events.grf_channels": {"left": "Fz1", "right": "Fz2"},
    "events.foot_markers": {"left": "LCAL", "right": "RCAL"},
    "events.plate_sides": {"left": 2, "right": 1},
    "device.mat_column_map": {"time_s": "time"},
    "dynamics.foot_bodies.left": "toes_l",
    "dynamics.foot_bodies.right": "toes_r",
}

#: Config key -> the rules that read it (the front page reads the run's headline settings).
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
        "all dynamics_trials front_page impedance_figures impedance_fit impedance_table planning strides_summary "
        "synthetic_lab"
    ),
    "study.perturbation_repeats": (
        "all dynamics_trials front_page impedance_fit planning strides_summary synthetic_lab"
    ),
    "study.perturbed_side": "front_page model_segments strides synthetic_lab transparency",
    "synthetic.walking_duration_s": "front_page synthetic_lab",
    "synthetic.static_duration_s": "synthetic_lab",
    "synthetic.variability": "front_page synthetic_lab",
    "synthetic.timing_cv": "synthetic_lab",
    "synthetic.amplitude_cv": "synthetic_lab",
    "synthetic.study_variability": "synthetic_lab",
    "synthetic.device_adaptation": "synthetic_lab",
    "synthetic.marker_noise_sd_m": "synthetic_lab",
    "synthetic.marker_gaps_per_trial": "synthetic_lab",
    "synthetic.max_gap_frames": "synthetic_lab",
    "synthetic.grf_noise_sd_n": "synthetic_lab",
    "synthetic.clock_offset_s": "synthetic_lab",
    "synthetic.clock_drift_ppm": "synthetic_lab",
    "synthetic.pulse_force_n": "front_page synthetic_lab",
    "synthetic.pulse_duration_s": "front_page synthetic_lab",
    "synthetic.perturb_every_strides": "synthetic_lab",
    "synthetic.between_subject_cv": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.50": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.175": "synthetic_truth",
    "synthetic.stiffness_nm_per_rad.300": "synthetic_truth",
    "synthetic.damping_nms_per_rad.50": "synthetic_truth",
    "synthetic.damping_nms_per_rad.175": "synthetic_truth",
    "synthetic.damping_nms_per_rad.300": "synthetic_truth",
    "markers.lab_to_model_rotation_deg": "events events_loadcell grf markers model_generic model_scaled synthetic_lab",
    "markers.walking_direction": "markers",
    "markers.min_travel_speed_m_per_s": "markers",
    "markers.max_gap_frames": "markers",
    "model.static_duration_s": "model_generic model_scaled",
    "model.static_max_motion_rms_m": "model_scaled",
    "markers.extent_range_m": "markers",
    "markers.label_map": "events events_loadcell markers",
    "markers.trial_label_maps": "events events_loadcell markers",
    "markers.trial_spans_s": "markers",
    "markers.filter.cutoff_hz": "events_loadcell front_page markers planning",
    "markers.filter.order": "events events_loadcell front_page markers planning",
    "model.generic_model": "model_scaled",
    "model.scale_setup": "model_scaled",
    "model.segment_bodies": "model_scaled model_segments",
    "model.brace_attachment_fraction": "model_segments",
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
    "model.scale_factor_range": "model_scaled",
    "ik.ik_chunks": "ik ik_chunk ik_join",
    "ik.coordinate_map": "dynamics ik model_scaled",
    "grf.loaded_threshold_n": "grf",
    "grf.resting_band_n": "events events_loadcell grf",
    "grf.max_resting_n": "events events_loadcell grf",
    "events.grf_channels": "events events_loadcell",
    "events.sync_channel": "events_loadcell synthetic_lab",
    "events.threshold_on_n": "events events_loadcell",
    "events.threshold_off_n": "events events_loadcell",
    "events.min_stance_s": "events events_loadcell",
    "events.min_swing_s": "events events_loadcell",
    "events.foot_markers": "events events_loadcell",
    "events.plate_sides": "events events_loadcell",
    "events.grf_cutoff_hz": "events events_loadcell",
    "strides.n_points": "dynamics strides",
    "dynamics.cutoff_hz": "dynamics",
    "dynamics.foot_bodies.left": "dynamics",
    "dynamics.foot_bodies.right": "dynamics",
    "strides.iqr_whisker": "impedance_fit planning strides",
    "strides.max_outlier_fraction": "impedance_fit planning strides",
    "strides.min_valid_strides": "impedance_fit planning strides strides_summary transparency",
    "impedance.window_before_s": "front_page impedance_fit planning validation_chunk",
    "impedance.window_after_s": "front_page impedance_fit planning validation_chunk",
    "impedance.stiffness_bounds_nm_per_rad": (
        "front_page impedance_fit impedance_summary planning synthetic_truth validation_chunk"
    ),
    "impedance.damping_bounds_nms_per_rad": (
        "front_page impedance_fit impedance_summary planning synthetic_truth validation_chunk"
    ),
    "impedance.n_starts": "front_page impedance_fit validation_chunk",
    "impedance.n_substeps": "impedance_fit planning validation_chunk",
    "impedance.tolerance": "impedance_fit validation_chunk",
    "impedance.merge_tolerance": "impedance_fit validation_chunk",
    "impedance.initial_state_span_s": "impedance_fit planning validation_chunk",
    "impedance.initial_state_degree": "impedance_fit planning validation_chunk",
    "impedance.min_vaf_pct": "impedance_fit",
    "impedance.max_null_trial_ratio": "impedance_fit planning",
    "impedance.plausible_ranges": "impedance_fit",
    "impedance.max_ci_fraction": "impedance_fit",
    "impedance.noise_model": "front_page impedance_fit",
    "impedance.counterfactual": "impedance_fit planning",
    "impedance.interval_scatter": "impedance_fit planning",
    "impedance.averaging_correction": "impedance_fit",
    "impedance.null_pair_components": "front_page impedance_fit planning",
    "impedance.min_null_pairs": "impedance_fit planning",
    "planning.pilot_subject": "planning",
    "planning.strides": "planning",
    "planning.pulse_force_n": "events_loadcell planning",
    "planning.pulse_duration_s": "planning",
    "planning.targets": "planning",
    "validation.subject_height_m": "validation_segments",
    "validation.subject_mass_kg": "validation_segments",
    "validation.attachment_fraction_of_thigh": "validation_segments",
    "validation.stiffness_levels_nm_per_rad": "validation_chunk",
    "validation.damping_levels_nms_per_rad": "validation_chunk",
    "validation.sample_rate_hz": "validation_chunk",
    "validation.swing_duration_s": "validation_chunk",
    "validation.onset_s": "validation_chunk",
    "validation.pulse_force_n": "validation_chunk",
    "validation.pulse_duration_s": "validation_chunk",
    "validation.pulse_rise_time_s": "validation_chunk",
    "validation.pulse_overshoot_pct": "validation_chunk",
    "validation.force_rate_hz": "validation_chunk",
    "validation.force_direction_deg": "validation_chunk",
    "validation.noise_peak_to_peak": "validation_chunk",
    "validation.truth_substeps": "validation_chunk",
    "validation.n_chunks": "validation_chunk validation_gather",
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
}


def _keys(node: dict, prefix: tuple = ()):
    for key, value in node.items():
        if isinstance(value, dict) and value and key not in MAPPINGS:
            yield from _keys(value, prefix + (key,))
        else:
            yield prefix + (key,), value


def _changed(key: tuple, value):
    """A valid other value: the listed change, else a nudge (a flag flipped, a number up by 10 %, a count by 1,
    another choice of the schema)."""
    name = ".".join(map(str, key))
    if name in CHANGES:
        return CHANGES[name]
    if isinstance(value, bool):
        return not value
    if isinstance(value, int):
        return value + 1
    if isinstance(value, float):
        return value * 1.1 if value else 0.01
    if isinstance(value, list):
        return [x + 1 if isinstance(x, int) else x * 1.1 for x in value]
    if isinstance(value, dict):  # a mapping: its first entry changed
        first = next(iter(value))
        return {**value, first: _changed((*key, first), value[first])}
    return _schema_choices(key, value)


def _schema_choices(key: tuple, value):
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    node = schema
    for k in key:
        node = node["properties"][k]
        if "$ref" in node:
            node = {**schema["definitions"][node["$ref"].split("/")[-1]], **node}
    return next(v for v in node["enum"] if v != value)


def _nested(key: tuple, value) -> dict:
    for k in reversed(key):
        value = {k: value}
    return value


#: Dotted name -> (key path, value) of every setting.
SETTINGS = {".".join(map(str, k)): (k, v) for k, v in _keys(CONFIG) if ".".join(map(str, k)) not in NOT_SETTINGS}


def test_every_setting_has_its_readers_listed():
    assert sorted(SETTINGS) == sorted(READERS)


@pytest.fixture(scope="module")
def base() -> dict[str, str]:
    return rule_signatures(ROOT, {})


@pytest.mark.parametrize("name", SETTINGS)
def test_a_changed_setting_changes_exactly_the_rules_that_read_it(base, name):
    key, value = SETTINGS[name]
    changed = rule_signatures(ROOT, _nested(key, copy.deepcopy(_changed(key, value))))
    rerun = {rule for rule in set(base) | set(changed) if base.get(rule) != changed.get(rule)}
    assert rerun - {"all"} == set(READERS[name].split()) - {"all"}


#: Keys that shape the whole study (which subjects, trials and files there are), not one stage's settings.
STUDY_KEYS = {"raw_dir", "seed", "study.static", "study.no_device", "study.device", "study.perturbation_onsets_ms"}
STUDY_KEYS |= {"study.perturbation_repeats"}


def _stage_rows() -> dict[str, list[str]]:
    """Stage (its rule file) -> the config patterns of its row in ``docs/code_layout.md``'s stage table."""
    rows = {}
    for line in (ROOT / "docs" / "code_layout.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 6 and cells[1].startswith("`") and cells[1].endswith(".smk`"):
            rows[cells[1].strip("`").removesuffix(".smk")] = re.findall(r"`([^`]+)`", cells[5])
    return rows


def test_each_stages_row_lists_the_settings_its_rules_read():
    """The config column of the stage table: every setting a stage's rules read matches one of its patterns."""
    rows = _stage_rows()
    stages = sorted(p.stem for p in (ROOT / "workflow" / "rules").glob("*.smk") if p.stem not in ("common", "inputs"))
    assert sorted(rows) == stages
    missing = {}
    for stage, patterns in rows.items():
        rules = set(re.findall(r"^\s*rule (\w+):", (ROOT / "workflow" / "rules" / f"{stage}.smk").read_text(), re.M))
        read = {k for k, readers in READERS.items() if rules & set(readers.split())} - STUDY_KEYS
        unlisted = sorted(k for k in read if not any(fnmatch.fnmatch(k, p) for p in patterns))
        unread = sorted(p for p in patterns if not any(fnmatch.fnmatch(k, p) for k in read))
        if unlisted or unread:
            missing[stage] = unlisted + [f"{p} (read by none)" for p in unread]
    assert missing == {}
