"""The options of the ``loper-analysis`` command: each stage's subcommands, then ``inspect``.

The stages' subcommands live in their slices (``loper_analysis.stages.<name>.command``, gathered by
:func:`loper_analysis.stages.command.stage_commands` in the order of the stages); ``inspect``, which belongs to no
stage, adds its parser here. :func:`build_parser` builds the whole parser with the subcommands' handlers
(:mod:`loper_analysis.cli`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Mapping

from loper_analysis.cli_options import add_configfile_option
from loper_analysis.stages.command import Command, stage_commands

__all__ = ["STAGE_COMMANDS", "SUBCOMMANDS", "build_parser"]

#: The stages' subcommands, in the order of the stages.
STAGE_COMMANDS: tuple[Command, ...] = stage_commands()
#: The subcommands, in the order ``--help`` lists them: the stages', then ``inspect``.
SUBCOMMANDS: tuple[str, ...] = (*(c.name for c in STAGE_COMMANDS), "inspect")


def _add_inspect(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``inspect`` subcommand."""
    p = sub.add_parser(
        "inspect",
        help="what a lab's C3D files hold; a subject's config from a marker-set template, or labels matched to a model",
        description="Without --model: a subject's files (static and walking trials, their kinds from their names) "
        "are matched to the marker-set templates, and --config-out writes the subject's config with the model, "
        "marker set, ScaleTool setup, IK tasks and label map beside it. With --model: one file's labels matched "
        "to that model's markers, a starter label map and a config snippet.",
    )
    p.add_argument("c3d", nargs="+", help="the lab's C3D file(s) of one subject (static.c3d, walk-nodevice.c3d, ...)")
    p.add_argument("--model", metavar="M.osim", help="OpenSim model whose markers the file's labels are matched to")
    p.add_argument("--marker-set", metavar="SET.xml", help="OpenSim MarkerSet whose markers are added to the model's")
    p.add_argument(
        "--label-map-out", metavar="MAP.tsv", help="write the starter label map (label, marker; needs --model)"
    )
    p.add_argument(
        "--label-map",
        metavar="MAP.tsv",
        help="without --model: the lab's label map (label, marker; TSV or YAML), applied before the labels are "
        "matched to the templates, e.g. a completed label_map_starter.tsv (rows left empty are skipped); "
        "default: markers.label_map of the config",
    )
    p.add_argument(
        "--config-out",
        metavar="CONFIG.yaml",
        help="without --model: the subject's config (files it names beside it); with --model: a config snippet "
        "(rotation, label map, heel markers, model) to merge over the configuration",
    )
    add_configfile_option(p)
    p.set_defaults(func=handlers["inspect"])


def build_parser(handlers: Mapping[str, Callable], description: str = "") -> argparse.ArgumentParser:
    """The command's parser; ``handlers`` maps each of :data:`SUBCOMMANDS` to the function that runs it
    (``args.func``)."""
    parser = argparse.ArgumentParser(prog="loper-analysis", description=description)
    parser.add_argument("--traceback", action="store_true", help="show the Python traceback of a failure")
    sub = parser.add_subparsers(dest="command", required=True)
    for command in STAGE_COMMANDS:
        p = sub.add_parser(command.name, help=command.help, description=command.description or None)
        command.add_arguments(p)
        p.set_defaults(func=handlers[command.name])
    _add_inspect(sub, handlers)
    return parser
