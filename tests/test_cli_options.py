"""cli_options.py: the options several subcommands share, parsed and turned into what a stage takes."""

from __future__ import annotations

import argparse

import pytest

from loper_analysis import cli_options
from loper_analysis.motion.trial_markers import MarkerSettings
from loper_analysis.stages.command import command_settings
from tests.config_layers import STRIDES


@pytest.fixture(scope="module")
def parser():
    p = argparse.ArgumentParser()
    cli_options.add_rotate_option(p, heading=True)
    cli_options.add_label_map_option(p)
    cli_options.add_configfile_option(p)
    return p


def test_the_rotation_given_else_the_configs_for_a_c3d_and_none_for_a_trc(parser):
    given = parser.parse_args(["--rotate-deg", "-90", "0", "90"])
    assert cli_options.rotation_option(given, "t.trc") == (-90.0, 0.0, 90.0)
    none = parser.parse_args([])
    assert cli_options.rotation_option(none, "T.C3D") is None
    assert cli_options.rotation_option(none, "t.trc") == (0.0, 0.0, 0.0)


def test_a_rotation_given_fixes_the_walking_direction_unless_one_is_given(parser):
    assert cli_options.walking_direction(parser.parse_args([])) is None
    assert cli_options.walking_direction(parser.parse_args(["--rotate-deg", "0", "0", "0"])) == "fixed"
    argv = ["--rotate-deg", "0", "0", "0", "--walking-direction", "auto"]
    assert cli_options.walking_direction(parser.parse_args(argv)) == "auto"


def test_a_label_map_is_read_only_when_given(parser, tmp_path):
    assert cli_options.label_map(parser.parse_args([]).label_map) is None
    (tmp_path / "map.tsv").write_text("label\tmarker\nLHEE\tL.Heel\n")
    assert cli_options.label_map(str(tmp_path / "map.tsv")) == {"LHEE": "L.Heel"}


def test_without_a_config_the_librarys_defaults_serve_and_the_line_says_so(parser, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    config, line = cli_options.read_config(parser.parse_args([]))
    assert config is None and line.startswith("config: none (no config/config.yaml in ")
    settings = command_settings(parser.parse_args([]), "markers", MarkerSettings(), order=2, cutoff_hz=None)
    assert settings == MarkerSettings(order=2)
    assert capsys.readouterr().out.startswith("config: none")


def test_config_files_layer_over_the_projects_and_a_file_named_twice_counts_last(parser, project, second):
    args = parser.parse_args(["--configfile", "config/config.yaml", str(second)])
    config, line = cli_options.read_config(args)
    assert line == "config: config/config.yaml, config/mine.yaml (later files override earlier ones)"
    assert config["planning"]["strides"] == STRIDES
