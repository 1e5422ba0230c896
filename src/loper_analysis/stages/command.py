"""A subcommand of ``loper-analysis`` as one record, and the stages' subcommands in the order of :data:`STAGES`.

A slice ``loper_analysis.stages.<name>`` with subcommands holds them in its
``command`` module as ``COMMANDS``; :func:`stage_commands` gathers them, so the
command's parser, handlers and option limits are built from the stages.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import importlib.util
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

from loper_analysis import cli_options
from loper_analysis.stages import STAGES
from loper_analysis.stages.settings import stage_settings

__all__ = ["Command", "stage_commands", "command_settings"]


@dataclass(frozen=True)
class Command:
    """One subcommand of ``loper-analysis``.

    Attributes
    ----------
    name : str
        The subcommand's name on the command line.
    help : str
        Its line in ``loper-analysis --help``.
    add_arguments : callable
        ``add_arguments(parser)`` adds its arguments to its own parser.
    run : callable
        ``run(args)`` runs it on the parsed command line.
    option_keys : mapping
        Its options with a config counterpart: option -> (schema file, key path); a value given is held to that
        key's limits (``subjects``: the subject sheet's schema).
    off_with_zero : frozenset of str
        Options of ``option_keys`` whose 0 switches their step off, whatever the key's limits.
    description : str
        The text of ``loper-analysis <name> --help``; empty: the help line serves.
    """

    name: str
    help: str
    add_arguments: Callable[[argparse.ArgumentParser], None]
    run: Callable[[argparse.Namespace], None]
    option_keys: Mapping[str, tuple[str, tuple[str, ...]]] = field(default_factory=dict)
    off_with_zero: frozenset[str] = frozenset()
    description: str = ""


def stage_commands() -> tuple[Command, ...]:
    """Every stage's subcommands (the ``COMMANDS`` of ``loper_analysis.stages.<name>.command``, for the stages that
    have that module), in the order of :data:`loper_analysis.stages.STAGES`."""
    commands: list[Command] = []
    for stage in STAGES:
        name = f"loper_analysis.stages.{stage.name}.command"
        if importlib.util.find_spec(name) is not None:
            commands += importlib.import_module(name).COMMANDS
    return tuple(commands)


def command_settings(args: argparse.Namespace, stage: str, default, part: str | None = None, **given):
    """A stage's settings for a subcommand: the config's (:func:`loper_analysis.cli_options.read_config`, its line
    printed; built by the stage's reader, :func:`loper_analysis.stages.settings.stage_settings`, and of them
    ``part`` when given), else ``default`` (the library's defaults); then each option in ``given`` that is not
    None."""
    config, line = cli_options.read_config(args)
    print(line)
    if config is None:
        settings = default
    else:
        settings = stage_settings(config, stage)
        settings = settings if part is None else getattr(settings, part)
    if config is not None and "label_map" in given and given["label_map"] is None:
        given["label_map"] = stage_settings(config, "markers").label_map
    return dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None})
