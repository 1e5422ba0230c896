"""The grf stage's subcommand: ``grf``, a C3D's force platforms as OpenSim external loads."""

from __future__ import annotations

import argparse

from loper_analysis import cli_options
from loper_analysis.stages.command import Command, command_settings

__all__ = ["COMMANDS"]


def _add_grf(p: argparse.ArgumentParser) -> None:
    """The ``grf`` subcommand's arguments."""
    p.add_argument("c3d", help="C3D file with a FORCE_PLATFORM group")
    p.add_argument("--out", required=True, help="output .mot (columns {n}_ground_force_v*, _p*, {n}_ground_torque_*)")
    cli_options.add_rotate_option(p)
    p.add_argument(
        "--threshold-n",
        type=float,
        help="loaded above this vertical force over rest (N; default: grf.loaded_threshold_n)",
    )
    cli_options.add_configfile_option(p)


def _grf(args: argparse.Namespace) -> None:
    from loper_analysis.gait.grf_settings import GRFSettings
    from loper_analysis.stages.grf.step import grf

    settings = command_settings(
        args,
        "grf",
        GRFSettings(),
        rotation_deg=cli_options.rotation_option(args, args.c3d),
        threshold_n=args.threshold_n,
    )
    table = grf(args.c3d, args.out, settings)
    n_plates = (table.shape[1] - 1) // 9
    print(f"{args.out}: {len(table)} samples, {n_plates} force platform(s)")


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="grf",
        help="C3D force platforms -> OpenSim external-loads .mot",
        add_arguments=_add_grf,
        run=_grf,
        option_keys={
            "threshold_n": ("config", ("grf", "loaded_threshold_n")),
            "rotate_deg": ("config", ("markers", "lab_to_model_rotation_deg")),
        },
    ),
)
