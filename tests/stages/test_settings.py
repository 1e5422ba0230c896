"""Each stage's settings reader (``stages/<stage>/settings.py``) against the shipped config: every key of the
config is read by exactly one reader, a reader takes the stages it needs from their readers, a missing key is
named with its section and reader, and the settings the workflow builds are those of the readers."""

from __future__ import annotations

import ast
import copy
import dataclasses
import importlib
import inspect
from collections.abc import Mapping

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.stages import STAGES
from loper_analysis.stages.settings import stage_settings
from tests.study_files import CONFIG

READERS = ["study", *(stage.name for stage in STAGES)]
#: Keys of the shipped config that no settings reader reads: the workflow's own (the rules' layout and the raw
#: folders' checks read them); each with where it is read.
NOT_SETTINGS: dict[str, str] = {}


class _Recording(Mapping):
    """A config whose sections' keys, when read, are recorded as ``section.key`` (top-level values as ``key``)."""

    def __init__(self, data: Mapping, read: set[str], path: str = ""):
        self._data, self._read, self._path = data, read, path

    def __getitem__(self, key):
        name = f"{self._path}.{key}" if self._path else key
        value = self._data[key]
        if isinstance(value, Mapping) and not self._path:
            return _Recording(value, self._read, name)
        self._read.add(name)
        return value

    def __iter__(self):
        return iter(self._data)

    def __len__(self):
        return len(self._data)


def _keys(config: Mapping) -> set[str]:
    """``section.key`` of every key of a section, and the top-level values."""
    out = set()
    for key, value in config.items():
        out |= {f"{key}.{k}" for k in value} if isinstance(value, Mapping) else {key}
    return out


def _read_by(name: str) -> set[str]:
    reader = importlib.import_module(f"loper_analysis.stages.{name}.settings")
    read: set[str] = set()
    reader.read_settings(_Recording(CONFIG, read), **{n: stage_settings(CONFIG, n) for n in reader.NEEDS})
    return read


def test_every_config_key_is_read_by_one_reader_or_named_as_no_setting():
    readers: dict[str, list[str]] = {}
    for name in READERS:
        for key in _read_by(name):
            readers.setdefault(key, []).append(name)
    twice = {key: names for key, names in readers.items() if len(names) > 1}
    assert twice == {}
    unread = _keys(CONFIG) - set(readers) - set(NOT_SETTINGS)
    assert unread == set()
    assert not set(NOT_SETTINGS) & set(readers)  # a key listed as no setting is not read by a reader after all
    assert set(NOT_SETTINGS) <= _keys(CONFIG)


def test_each_reader_needs_only_readers_that_exist_and_builds_without_its_needs_keys():
    for name in READERS:
        reader = importlib.import_module(f"loper_analysis.stages.{name}.settings")
        assert set(reader.NEEDS) <= set(READERS) - {name}, name
        assert stage_settings(CONFIG, name) is not None


@pytest.mark.parametrize(
    ("key", "reader", "asked"),
    [("impedance.counterfactual", "impedance", "planning"), ("study.perturbed_side", "study", "strides"),
     ("markers.filter.order", "markers", "events"), ("seed", "study", "validation")],
)  # fmt: skip
def test_a_missing_key_is_named_with_its_section_and_reader(key, reader, asked):
    config = copy.deepcopy(CONFIG)
    *sections, name = key.split(".")
    node = config
    for section in sections:
        node = node[section]
    del node[name]
    with pytest.raises(LoperInputError, match=f"^config: key '{key}' missing: the {reader} settings read it$"):
        stage_settings(config, asked)


def test_the_planner_models_the_load_cell_the_events_stage_filters_with():
    """``markers.filter.cutoff_hz`` and ``markers.filter.order`` reach the planner's model of the load cell, and the
    device's rate the planned force's."""
    config = copy.deepcopy(CONFIG)
    config["markers"]["filter"].update(cutoff_hz=25.0, order=2)
    config["device"]["parameters"]["sample_rate_hz"] = 500
    plan = stage_settings(config, "planning").plan
    loadcell = stage_settings(config, "events").loadcell
    assert (plan.force_cutoff_hz, plan.force_order) == (loadcell.cutoff_hz, loadcell.order) == (25.0, 2)
    assert plan.force_rate_hz == 500.0


#: Fields of the settings types that no reader sets, each a value the stage's code owns rather than a setting,
#: with why (the test below fails for any other field a reader leaves at its default).
NOT_SETTINGS_FIELDS = {
    "MarkerSettings.span_s": "a trial's span, given per trial by the markers rule (markers.trial_spans_s)",
    "MarkerSettings.duration_s": "an option of the markers step for a caller (keep the first seconds); the workflow "
    "keeps every frame",
    "MarkerSettings.required_markers": "an option of the markers step for a caller (markers that must be found)",
    "EventSettings.toe_markers": "the template's toe markers (model names); a file without them: found by name",
    "IKSettings.min_markers": "the fewest weighted markers that determine a frame: a property of the method",
    "EventSettings.label_map": "a trial's label maps, given per trial by the events rule",
    "IKSettings.subjects_model": "whether the model comes from the subject sheet, given per subject by the rule",
    "ModelSettings.time_range_s": "the static trial's window, from the ScaleTool setup or the scale command",
    "ResponseSettings.rate_hz": "the grid rate of the responses, the study's motion-capture rate (128 Hz)",
    "LabSettings.*": "the synthetic lab's rates, robot log margin and belt channels (documented defaults)",
    "ValidationSettings.reference_cutoff_hz": "the study fits the unfiltered reference (no config key)",
    "PlanSettings.coupling_bounds_nm_per_rad": "the couplings' bounds, a property of the physics (|K_hk| <= "
    "sqrt(K_hip K_knee), at most the stiffness bound), the fit's own (no config key)",
}


def _constructed_fields(reader, module) -> dict[str, set[str]]:
    """Settings type -> the fields its constructor gets in the reader's source: by keyword, by position (the
    first fields), or all of them when a mapping is unpacked into it (``**section``, every key of a section)."""
    tree = ast.parse(inspect.getsource(reader))
    out: dict[str, set[str]] = {}
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id[:1].isupper()):
            continue
        settings_type = getattr(module, node.func.id, None)
        if settings_type is None or not dataclasses.is_dataclass(settings_type):
            continue
        names = [f.name for f in dataclasses.fields(settings_type) if f.init]
        given = {k.arg for k in node.keywords if k.arg} | set(names[: len(node.args)])
        if any(k.arg is None for k in node.keywords):
            given = set(names)
        out.setdefault(node.func.id, set()).update(given)
    return out


@pytest.mark.parametrize("name", READERS)
def test_every_field_a_reader_builds_is_read_or_named_as_no_setting(name):
    """A field that a reader leaves at its default is either listed in NOT_SETTINGS_FIELDS, with why, or a
    setting whose key was forgotten (a key that silently does nothing, as the planner's load cell once did)."""
    reader = importlib.import_module(f"loper_analysis.stages.{name}.settings")
    built = {type(stage_settings(CONFIG, name)).__name__}
    for type_name, given in _constructed_fields(reader.read_settings, reader).items():
        settings_type = getattr(reader, type_name)
        left = {f.name for f in dataclasses.fields(settings_type) if f.init} - given
        unnamed = {
            f"{type_name}.{field}"
            for field in left
            if f"{type_name}.{field}" not in NOT_SETTINGS_FIELDS and f"{type_name}.*" not in NOT_SETTINGS_FIELDS
        }
        assert unnamed == set(), (name, built, unnamed)


# ---------------------------------------------------------------------------------------------------------------------
# the library's defaults: each stage's settings type, built with no argument, is what its reader builds of the
# shipped config, field by field and in every nested settings type, but for the fields named below

#: Fields whose shipped value is the study's choice, with no default in the library (None or empty there), and why.
STUDY_CHOICES = {
    "LabSessionSettings.truth": "the synthetic subjects' true impedance (the study's; the lab reads its truth.yaml)",
    "DeviceSettings.subject": "which subject's folder holds the device tests (None: no device tests)",
    "DeviceSettings.mat_column_map": "the names of a robot's .mat export (None: no export read)",
    "IdentificationSettings.seed": "the study's seed",
    "PlanningSettings.onsets_ms": "the study's onsets (None: the pilot's)",
    "PlanningSettings.targets": "the precisions the study asks for",
}


def _default_map(value):
    """The library's default for ``None`` of a coordinate map, as the config spells a map."""
    from loper_analysis.motion.ik import DEFAULT_COORDINATE_MAP

    return {a: {"coordinate": c, "sign": s} for a, (c, s) in DEFAULT_COORDINATE_MAP.items()} if value is None else value


def _default_ranges(value):
    """The library's default for ``None`` of the plausible ranges, as the config spells them."""
    from loper_analysis.impedance.identification import DEFAULT_PLAUSIBLE_RANGES

    if value is not None:
        return value
    names = ("stiffness_nm_per_rad", "damping_nms_per_rad")
    return {joint: dict(zip(names, ranges, strict=True)) for joint, ranges in DEFAULT_PLAUSIBLE_RANGES.items()}


#: Fields whose default None (or empty) stands for the value the shipped config spells out: how to read it.
SAME_MEANING = {
    "ModelSettings.coordinate_map": _default_map,
    "IKSettings.coordinate_map": _default_map,
    "DynamicsSettings.coordinate_map": _default_map,
    "IKSettings.marker_weights": lambda value: value or {},
    "IKSettings.coordinate_tasks": lambda value: value or {},
    "IdentificationSettings.plausible_ranges": _default_ranges,
}


def _plain(value):
    if isinstance(value, list | tuple):
        return tuple(_plain(v) for v in value)
    if isinstance(value, Mapping):
        return {k: _plain(v) for k, v in value.items()}
    return value


def _differing(default, built) -> set[str]:
    """``Type.field`` of every field (in nested settings types too) where ``default`` and ``built`` differ, as read
    through :data:`SAME_MEANING`."""
    out = set()
    for f in dataclasses.fields(default):
        name = f"{type(default).__name__}.{f.name}"
        have, want = getattr(default, f.name), getattr(built, f.name)
        if dataclasses.is_dataclass(have) and type(have) is type(want):
            out |= _differing(have, want)
            continue
        read = SAME_MEANING.get(name, lambda value: value)
        if _plain(read(have)) != _plain(read(want)):
            out.add(name)
    return out


@pytest.mark.parametrize("name", [stage.name for stage in STAGES if stage.name != "report"])
def test_the_librarys_defaults_are_what_the_shipped_config_builds(name):
    """A direct call of the library and the workflow at its shipped config compute with the same numbers. The
    report's settings have no default (its run settings are the other stages'), the study's neither."""
    built = stage_settings(CONFIG, name)
    assert _differing(type(built)(), built) == {key for key in STUDY_CHOICES if _owner(key, built)}


def _owner(key: str, settings) -> bool:
    """Whether ``Type.field`` belongs to ``settings`` or a settings type nested in it."""
    type_name = key.split(".")[0]
    if type(settings).__name__ == type_name:
        return True
    return any(
        dataclasses.is_dataclass(getattr(settings, f.name)) and _owner(key, getattr(settings, f.name))
        for f in dataclasses.fields(settings)
    )


def test_a_changed_default_or_config_value_is_found():
    from loper_analysis.device.controller import DeviceParameters

    built = stage_settings(CONFIG, "device")
    changed = dataclasses.replace(built, parameters=dataclasses.replace(built.parameters, servo_delay_s=0.003))
    assert _differing(type(built)(), changed) - set(STUDY_CHOICES) == {"DeviceParameters.servo_delay_s"}
    assert DeviceParameters().servo_delay_s == CONFIG["device"]["parameters"]["servo_delay_s"] != 0.003
    config = copy.deepcopy(CONFIG)
    config["markers"]["filter"]["cutoff_hz"] = 12.0
    assert _differing(type(built := stage_settings(config, "markers"))(), built) == {"MarkerSettings.cutoff_hz"}
