"""Each config key reruns exactly the rules that read it: every setting of ``config/config.yaml`` changed in turn,
and the rules whose params or files change (what Snakemake's params and input triggers rerun) compared with the
readers each stage lists in ``tests/stages/<stage>/config_readers.py``. A setting that reran a rule not reading it
would redo work (and, upstream, everything after it); one that reran none would be a setting nothing reads."""

from __future__ import annotations

import copy
import fnmatch
import importlib
import importlib.util
import re
from pathlib import Path

import pytest
import yaml

from loper_analysis.stages import STAGES
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
    "impedance.couplings": ["hip_knee"],
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
    "report.calibration": "config/calibration/other.tsv",
}

#: Config key -> the rules that read it (the front page reads the run's headline settings): each stage's own keys in
#: ``tests/stages/<stage>/config_readers.py`` (the study's and the top-level keys in ``tests/stages/study/``).
READERS = {
    key: rules
    for name in ("study", *(stage.name for stage in STAGES))
    if importlib.util.find_spec(f"tests.stages.{name}.config_readers") is not None
    for key, rules in importlib.import_module(f"tests.stages.{name}.config_readers").READERS.items()
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


def test_each_stages_readers_are_its_own_sections_keys():
    """A stage's file of readers lists the keys of its own section only (the study's: its section and the
    top-level keys), so that a stage's keys and their rules live with its tests."""
    for name in ("study", *(stage.name for stage in STAGES)):
        if importlib.util.find_spec(f"tests.stages.{name}.config_readers") is None:
            continue
        keys = importlib.import_module(f"tests.stages.{name}.config_readers").READERS
        own = {k for k in keys if k.split(".")[0] == name or (name == "study" and "." not in k)}
        assert set(keys) == own, name
