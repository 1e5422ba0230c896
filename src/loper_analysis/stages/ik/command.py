"""The ik stage's subcommand: ``ik``, inverse kinematics of a marker file to joint angles."""

from __future__ import annotations

import argparse
import dataclasses
import sys

from loper_analysis import cli_options
from loper_analysis.stages.command import Command

__all__ = ["COMMANDS"]


class _FormerAccuracy(argparse.Action):
    """The former ``--accuracy``, one value for both solvers: refused, naming the two options that replace it."""

    def __call__(self, parser, namespace, values, option_string=None):
        parser.error(
            "--accuracy is no longer an option (it set two different things): give --tree-step-tolerance (the tree "
            "solver's step, rad or m; ik.tree_step_tolerance) and/or --opensim-accuracy (OpenSim's solver's "
            "accuracy; ik.opensim_accuracy)"
        )


def _add_ik(p: argparse.ArgumentParser) -> None:
    """The ``ik`` subcommand's arguments."""
    p.add_argument("--model", required=True, help="OpenSim model (.osim)")
    p.add_argument("--markers", required=True, help="marker file: .c3d (units from POINT:UNITS) or .trc (Units header)")
    p.add_argument("--out", required=True, help="output .mot (angles in degrees, OpenSim's convention)")
    p.add_argument(
        "--tasks",
        help="OpenSim IK task-set XML or TSV (name, kind, weight[, value]); default: ik.ik_tasks, else "
        "every model marker found in the file, weight 1",
    )
    p.add_argument("--start", type=float, help="first time (s) to solve")
    p.add_argument("--end", type=float, help="last time (s) to solve")
    cli_options.add_label_map_option(p)
    cli_options.add_rotate_option(p, heading=True)
    p.add_argument(
        "--tree-step-tolerance",
        type=float,
        help="the tree solver stops a frame when its last step moved no coordinate by more than this (rad or m; "
        "default: ik.tree_step_tolerance)",
    )
    p.add_argument(
        "--opensim-accuracy",
        type=float,
        help="accuracy of OpenSim's IK solver, unitless: roughly the number of correct digits asked of the "
        "weighted objective's minimum (default: ik.opensim_accuracy; OpenSim's own default 1e-5)",
    )
    p.add_argument("--accuracy", action=_FormerAccuracy, help=argparse.SUPPRESS)
    p.add_argument(
        "--solver",
        choices=("tree", "opensim"),
        help="IK solver (default: ik.ik_solver): the model's kinematic tree or OpenSim's",
    )
    p.add_argument(
        "--max-marker-rms-m",
        type=float,
        help="a frame whose marker RMS error exceeds this (m) counts as failed (a unit, label or model mistake; "
        "default: ik.max_marker_rms_m)",
    )
    p.add_argument(
        "--warn-marker-rms-m",
        type=float,
        help="a frame whose marker RMS error exceeds this (m) counts as poorly fitted (a warning; default: "
        "ik.warn_marker_rms_m)",
    )
    p.add_argument(
        "--max-rms-fraction",
        type=float,
        help="fail (warn) when more frames than this share fail (fit poorly; default: ik.max_rms_fraction)",
    )
    cli_options.add_configfile_option(p)


def _ik(args: argparse.Namespace) -> None:
    import numpy as np

    from loper_analysis.io.readers import read_label_maps
    from loper_analysis.motion.ik_settings import IKSettings
    from loper_analysis.stages.ik.step import ik_file
    from loper_analysis.stages.markers.step import MarkerSettings
    from loper_analysis.stages.settings import stage_settings

    config, line = cli_options.read_config(args)
    print(line)
    settings = IKSettings() if config is None else stage_settings(config, "ik")
    given = {
        "tasks_file": args.tasks,
        "tree_step_tolerance": args.tree_step_tolerance,
        "opensim_accuracy": args.opensim_accuracy,
        "solver": args.solver,
        "max_marker_rms_m": args.max_marker_rms_m,
        "warn_marker_rms_m": args.warn_marker_rms_m,
        "max_rms_fraction": args.max_rms_fraction,
    }
    settings = dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None}, subjects_model=False)
    # a C3D holds the lab's labels in the lab's frame (the config's markers.*); a TRC the model's already
    lab = MarkerSettings() if config is None else stage_settings(config, "markers")
    label_map = cli_options.label_map(args.label_map)
    if label_map is None and config is not None and str(args.markers).lower().endswith(".c3d"):
        label_map = read_label_maps(stage_settings(config, "markers").label_map)
    result = ik_file(
        args.model,
        args.markers,
        args.out,
        settings,
        (args.start, args.end),
        cli_options.rotation_option(args, args.markers) or lab.rotation_deg,
        label_map,
        cli_options.walking_direction(args) or lab.walking_direction,
    )
    left_out = f", {result.n_left_out} left out (too few markers)" if result.n_left_out else ""
    print(
        f"{args.out}: {len(result.time_s)} frames{left_out}, marker error RMS "
        f"{1e3 * np.nanmean(result.marker_rms_m):.2f} mm (max {1e3 * np.nanmax(result.marker_max_m):.2f} mm)"
    )
    if result.warning:
        print(f"warning: {result.warning}", file=sys.stderr)


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="ik",
        help="OpenSim inverse kinematics of a .c3d or .trc marker file to a .mot (degrees)",
        add_arguments=_add_ik,
        run=_ik,
        option_keys={
            "rotate_deg": ("config", ("markers", "lab_to_model_rotation_deg")),
            "tree_step_tolerance": ("config", ("ik", "tree_step_tolerance")),
            "opensim_accuracy": ("config", ("ik", "opensim_accuracy")),
            "max_marker_rms_m": ("config", ("ik", "max_marker_rms_m")),
            "warn_marker_rms_m": ("config", ("ik", "warn_marker_rms_m")),
            "max_rms_fraction": ("config", ("ik", "max_rms_fraction")),
        },
    ),
)
