"""config_file.py: the workflow's configuration read outside Snakemake, layered as Snakemake layers
``--configfile`` files and ``--config`` values, and checked against the project's schema."""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path

import pytest
import yaml

from loper_analysis.config_file import (
    config_layers,
    find_schema,
    load_config,
    read_config_file,
    shown_path,
    update_config,
)
from loper_analysis.errors import LoperInputError
from tests.config_layers import STRIDES, WINDOW_AFTER_S, write_yaml

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"

# --------------------------------------------------------------------------- load_config


def test_later_file_updates_the_earlier_recursively(project, second):
    base = yaml.safe_load(CONFIG.read_text())
    config, used = load_config(["config/config.yaml", second])
    assert used == ["config/config.yaml", "config/mine.yaml"]
    assert config["impedance"]["window_after_s"] == WINDOW_AFTER_S and config["planning"]["strides"] == STRIDES
    # keys the second file does not name keep the first file's values, at every depth
    assert config["impedance"]["window_before_s"] == base["impedance"]["window_before_s"]
    assert config["planning"]["targets"] == base["planning"]["targets"]
    assert config["device"] == base["device"]
    # overrides come last; the default file is config/config.yaml of the working directory
    config, used = load_config(overrides={"planning": {"pulse_force_n": 55.0}})
    assert used == ["config/config.yaml"] and config["planning"]["pulse_force_n"] == 55.0
    assert config["planning"]["strides"] == base["planning"]["strides"]


def test_update_is_snakemakes():
    snakemake_utils = pytest.importorskip("snakemake.utils")
    base = {"a": {"b": 1, "c": [1, 2], "d": None}, "e": 2, "f": {"g": 1}}
    for over in ({"a": {"c": [3]}}, {"a": {"d": {"x": 1}}}, {"f": 5}, {"e": {"h": {"i": 1}}}, {"a": {}}, {}):
        ours, theirs = copy.deepcopy(base), copy.deepcopy(base)
        update_config(ours, over)
        snakemake_utils.update_config(theirs, over)
        assert ours == theirs, over


def test_bad_key_in_the_second_file_is_named_with_that_file(project):
    bad = write_yaml(project / "second.yaml", {"planning": {"stridez": [3]}})
    with pytest.raises(LoperInputError, match=r"^second\.yaml: key 'planning\.stridez': Additional properties"):
        load_config(["config/config.yaml", bad])
    bad = write_yaml(project / "second.yaml", {"impedance": {"window_after_s": -0.1}})
    with pytest.raises(LoperInputError, match=r"^second\.yaml: key 'impedance\.window_after_s': -0\.1 is "):
        load_config(["config/config.yaml", bad])
    # a value the first file sets is named with the first file
    (project / "config" / "config.yaml").write_text(CONFIG.read_text().replace("n_starts: 10 ", "n_starts: ten "))
    with pytest.raises(LoperInputError, match=r"^config/config\.yaml: key 'impedance\.n_starts': 'ten'"):
        load_config(["config/config.yaml", write_yaml(project / "ok.yaml", {"seed": 1})])


def test_yaml_syntax_error_names_the_file_and_line(project):
    (project / "broken.yaml").write_text("planning:\n  strides: [10, 20\n  pulse_force_n: 40\n")
    with pytest.raises(LoperInputError, match=r"broken\.yaml: line \d+, column \d+: YAML syntax error"):
        load_config(["config/config.yaml", "broken.yaml"])


def test_schema_of_the_config_files_project_wins(project, tmp_path_factory):
    other = tmp_path_factory.mktemp("other")
    (other / "config").mkdir()
    (other / "workflow" / "schemas").mkdir(parents=True)
    write_yaml(other / "workflow" / "schemas" / "config.schema.yaml", {"type": "object", "required": ["only_key"]})
    path = write_yaml(other / "config" / "config.yaml", {"seed": 1})
    assert find_schema([path]) == other / "workflow" / "schemas" / "config.schema.yaml"
    with pytest.raises(LoperInputError, match=r"config\.yaml: key '\(top level\)': 'only_key' is a required"):
        load_config([path])
    # no project folder beside the file: the working directory's
    assert find_schema([other / "loose.yaml"]) == project / "workflow" / "schemas" / "config.schema.yaml"


# --------------------------------------------------------------------------- one file, as Snakemake reads it


def _refused(message: str):
    return pytest.raises(LoperInputError, match="^" + re.escape(message) + "$")


def test_a_key_given_twice_is_named_with_both_lines(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("c.yaml").write_text("seed: 1\nplanning:\n  strides: [10]\n  pulse_force_n: 40\n  strides: [20]\n")
    with _refused(
        "c.yaml: key 'planning.strides' is given twice in the config file, at line 3, column 3 and line 5, "
        "column 3: YAML keeps the second, which replaces the first whole; merge them"
    ):
        read_config_file("c.yaml")


def test_json_and_yaml_files_read_alike_and_other_tops_are_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    data = {"seed": 3, "planning": {"strides": [10, 20], "pulse_force_n": 40.5}}
    Path("c.json").write_text(json.dumps(data))
    Path("c.yaml").write_text(yaml.safe_dump(data))
    assert read_config_file("c.json") == read_config_file("c.yaml") == data
    Path("list.yaml").write_text("- 1\n- 2\n")
    with _refused(
        "list.yaml: the config file must hold keys at its top level (key: value), found a sequence at line 1, column 1"
    ):
        read_config_file("list.yaml")


def test_a_yte_template_is_refused_and_a_false_flag_dropped(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("t.yaml").write_text("__use_yte__: true\nseed: 1\n")
    with _refused(
        "t.yaml: line 1, column 1: key '__use_yte__': a YTE template, whose expressions Snakemake would run as "
        "Python: refused; the config file must hold the plain values (render it yourself if you trust it)"
    ):
        read_config_file("t.yaml")
    Path("t.yaml").write_text("__use_yte__: false\nseed: 1\n")
    assert read_config_file("t.yaml") == {"seed": 1}


def test_no_file_given_is_refused():
    with _refused("load_config: no configuration file given"):
        load_config([])


def test_overrides_win_over_every_file_and_are_not_changed(project, second):
    overrides = {"planning": {"strides": [3]}}
    config, _ = load_config(["config/config.yaml", second], overrides)
    assert config["planning"]["strides"] == [3]
    assert config["impedance"]["window_after_s"] == WINDOW_AFTER_S
    config["planning"]["strides"].append(4)
    assert overrides == {"planning": {"strides": [3]}}


def test_shown_path_is_relative_inside_the_working_directory(tmp_path, monkeypatch):
    (tmp_path / "sub").mkdir()
    monkeypatch.chdir(tmp_path / "sub")
    assert shown_path(tmp_path / "sub" / "config" / "a.yaml") == str(Path("config") / "a.yaml")
    assert shown_path(tmp_path / "b.yaml") == str(tmp_path / "b.yaml")


def test_config_layers_put_the_command_line_first_and_the_last_file_next(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    read = {"a.yaml": {"seed": 1}, "b.yaml": None}
    layers = config_layers({"seed": 9}, ["a.yaml", "b.yaml"], read.__getitem__)
    assert layers == [("--config", {"seed": 9}), ("b.yaml", {}), ("a.yaml", {"seed": 1})]


def test_no_schema_anywhere_names_where_it_was_looked_for(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(LoperInputError, match=r"^x/config/c\.yaml: cannot validate: no workflow/schemas/nope\.yaml"):
        find_schema([tmp_path / "x" / "config" / "c.yaml"], "nope.yaml")
