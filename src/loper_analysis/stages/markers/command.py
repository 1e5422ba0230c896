"""The markers stage's subcommand: ``markers``, a C3D's markers as a TRC in the model's names and frame."""

from __future__ import annotations

import argparse
import dataclasses

from loper_analysis import cli_options
from loper_analysis.stages.command import Command, command_settings

__all__ = ["COMMANDS"]


def _add_markers(p: argparse.ArgumentParser) -> None:
    """The ``markers`` subcommand's arguments."""
    p.add_argument("c3d", help="marker file (.c3d)")
    p.add_argument("--out", required=True, help="output .trc")
    p.add_argument("--gaps", help="output TSV: per marker, frames filled and left missing")
    cli_options.add_label_map_option(p)
    cli_options.add_rotate_option(p, heading=True)
    p.add_argument(
        "--cutoff-hz",
        type=float,
        help="zero-phase Butterworth low-pass (Hz); 0: no filter (default: markers.filter.cutoff_hz)",
    )
    p.add_argument(
        "--order", type=int, help="designed filter order, run forward and backward (default: markers.filter.order)"
    )
    p.add_argument(
        "--max-gap-frames",
        type=int,
        help="fill gaps up to this many frames; 0: no filling (default: markers.max_gap_frames)",
    )
    cli_options.add_configfile_option(p)


def _markers(args: argparse.Namespace) -> None:
    from loper_analysis.stages.markers.step import MarkerSettings, markers

    settings = command_settings(
        args,
        "markers",
        MarkerSettings(),
        rotation_deg=cli_options.rotation_option(args, args.c3d),
        walking_direction=cli_options.walking_direction(args),
        cutoff_hz=args.cutoff_hz,
        order=args.order,
        max_gap_frames=args.max_gap_frames,
        label_map=cli_options.label_map(args.label_map),
    )
    if not settings.cutoff_hz:
        settings = dataclasses.replace(settings, cutoff_hz=None)
    gaps = markers(args.c3d, args.out, args.gaps, settings)
    per_marker = gaps.attrs.get("per_marker", [])
    n_frames = per_marker[0]["n_frames"] if per_marker else 0
    missing = sum(row["n_missing_frames"] > 0 for row in per_marker)
    print(
        f"{args.out}: {len(per_marker)} markers, {n_frames} frames; {len(gaps)} gap(s) filled, "
        f"{missing} marker(s) still missing somewhere"
    )


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="markers",
        help="C3D markers -> TRC (mm) in the model frame",
        add_arguments=_add_markers,
        run=_markers,
        option_keys={
            "cutoff_hz": ("config", ("markers", "filter", "cutoff_hz")),
            "order": ("config", ("markers", "filter", "order")),
            "max_gap_frames": ("config", ("markers", "max_gap_frames")),
            "rotate_deg": ("config", ("markers", "lab_to_model_rotation_deg")),
        },
        off_with_zero=frozenset({"cutoff_hz"}),
    ),
)
