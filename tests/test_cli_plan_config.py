"""``loper-analysis plan`` reads the workflow's configuration: the rule's settings, layered as Snakemake layers them.

:func:`loper_analysis.config_file.load_config` reads ``config/config.yaml``
and further files over it; the planner's settings come from one classmethod,
:meth:`loper_analysis.stages.planning.step.PlanningSettings.from_config`, which both
the rule ``planning`` (in ``workflow/rules/inputs.smk``) and the command call.
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import pandas as pd
import yaml

from loper_analysis.cli import _plan_pilot, _plan_settings, _read_config, command_parser, main
from loper_analysis.config_file import load_config
from loper_analysis.planning.window import PlanSettings
from loper_analysis.stages.planning.step import PlanningSettings
from loper_analysis.stages.settings import stage_settings
from tests.config_layers import STRIDES, WINDOW_AFTER_S, write_yaml

ROOT = Path(__file__).resolve().parents[1]
CONFIG = ROOT / "config" / "config.yaml"
SCHEMA = ROOT / "workflow" / "schemas" / "config.schema.yaml"

# --------------------------------------------------------------------------- one mapping for the rule and the command


def test_rule_takes_its_params_from_the_shared_builder():
    rules = ROOT / "workflow" / "rules"
    assert (
        'SETTINGS = {name: stage_settings(config, name) for name in ("study", *(stage.name for stage in STAGES))}'
        in (rules / "common.smk").read_text()
    )
    assert '**settings_params(SETTINGS["planning"]),' in (rules / "planning.smk").read_text()
    # the rule's script reads the pilot, its files and the one settings object, nothing else
    script = (ROOT / "workflow" / "scripts" / "planning.py").read_text()
    assert set(re.findall(r"\bp\.(\w+)", script)) == {"files", "subject", "settings"}


def test_command_and_rule_settings_are_one_for_the_same_config(project, second):
    config, _ = load_config(["config/config.yaml", second])
    rule = stage_settings(config, "planning")
    args = command_parser().parse_args(["plan", "--configfile", str(second)])
    read, line = _read_config(args)
    assert line == "config: config/config.yaml, config/mine.yaml (later files override earlier ones)"
    command = _plan_settings(args, read)
    assert command == rule
    # the config's values, not the library's defaults, reach the planner
    assert PlanSettings().window.after_s != WINDOW_AFTER_S and PlanningSettings().strides != tuple(STRIDES)
    assert command.plan.window.after_s == command.response.window.after_s == WINDOW_AFTER_S
    assert command.strides == tuple(STRIDES)
    assert command.onsets_ms == tuple(config["study"]["perturbation_onsets_ms"])
    assert _plan_pilot(args, read) == (
        config["planning"]["pilot_subject"],
        config["subjects"],
        [config["study"]["no_device"]],
    )


def test_options_given_override_the_config(project, second):
    args = command_parser().parse_args(
        [
            "plan",
            "--configfile",
            str(second),
            "--strides",
            "5",
            "--force-n",
            "30",
            "--onset-ms",
            "125",
            "--target",
            "hip",
            "K",
            "10",
        ]
    )
    settings = _plan_settings(args, _read_config(args)[0])
    assert settings.strides == (5,) and settings.plan.pulse_force_n == 30.0 and settings.onsets_ms == (125.0,)
    assert settings.targets == ({"joint": "hip", "parameter": "K", "percent": 10.0},)
    assert settings.plan.window.after_s == WINDOW_AFTER_S  # no option: the config's
    assert settings.plan.pulse_duration_s == stage_settings(load_config()[0], "planning").plan.pulse_duration_s


def test_without_a_config_the_library_defaults_serve_and_the_line_says_so(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = command_parser().parse_args(["plan"])
    config, line = _read_config(args)
    assert config is None
    assert line.startswith("config: none (no config/config.yaml in ") and "library defaults" in line
    assert _plan_settings(args, config) == PlanningSettings()
    assert _plan_pilot(args, config) == (None, "config/subjects.tsv", ["walk-nodevice"])


def test_command_prints_the_config_and_plans_with_its_window(project, capsys):
    """End to end: the config's fit window (shorter than the planned pulse) reaches the planner, which refuses it."""
    write_yaml(project / "short.yaml", {"identification": {"window_after_s": 0.05}})
    results = project / "results"
    for path in ("ik/S09/pert050-1.angles.tsv", "strides/S09/pert050-1.strides.tsv"):
        (results / path).parent.mkdir(parents=True, exist_ok=True)
        (results / path).write_text("")  # refused before any table is read
    code = main(["plan", "--configfile", "short.yaml", "--results", "results", "--subject", "S09"])
    captured = capsys.readouterr()
    assert code == 2
    assert captured.out == "config: config/config.yaml, short.yaml (later files override earlier ones)\n"
    assert "pulse_duration_s = 0.1 s is longer than the fit window after the onset" in captured.err
    assert "0.05" in captured.err


def test_validation_defaults_of_the_library_are_the_configs():
    from loper_analysis.impedance.identification.validation import ValidationSettings
    from loper_analysis.stages.settings import stage_settings

    config = yaml.safe_load(CONFIG.read_text())
    assert stage_settings(config, "validation") == ValidationSettings()


def test_validate_command_runs_with_the_configs_settings(project, capsys):
    """One K/D level (one combination): the config's levels reach the chunk, the option --n-starts wins."""
    from loper_analysis.io.segment_table import write_segments
    from tests.parameter_sets import WINTER

    write_segments(WINTER, project / "segments.tsv")
    (project / "lab.yaml").write_text(
        yaml.safe_dump(
            {
                "validation": {
                    "stiffness_levels_nm_per_rad": [75.0],
                    "damping_levels_nms_per_rad": [2.0],
                    "n_chunks": 1,
                },
                "seed": 11,
            }
        )
    )
    main(
        [
            "validate",
            "--configfile",
            "lab.yaml",
            "--n-starts",
            "2",
            "--segments",
            "segments.tsv",
            "--errors",
            "errors.tsv",
            "--fits",
            "fits.tsv",
        ]
    )
    assert (
        capsys.readouterr().out.splitlines()[0]
        == "config: config/config.yaml, lab.yaml (later files override earlier ones)"
    )
    fits = pd.read_csv(project / "fits.tsv", sep="\t")
    assert fits["combination"].nunique() == 1  # 1 level of K and D per joint: 1 combination, not the default 729


def test_planning_defaults_are_the_configs_but_onsets_and_targets():
    """Without a config the planner takes the onsets of the pilot's impedance rows and has no targets; every
    other setting of the library equals config/config.yaml's."""
    config = yaml.safe_load(CONFIG.read_text())
    built = stage_settings(config, "planning")
    assert dataclasses.replace(built, onsets_ms=None, targets=()) == PlanningSettings()
    assert built.onsets_ms == tuple(config["study"]["perturbation_onsets_ms"]) and built.targets
