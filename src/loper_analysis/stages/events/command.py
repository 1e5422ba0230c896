"""The events stage's subcommand: ``events``, heel strikes and toe-offs from the force platforms."""

from __future__ import annotations

import argparse

from loper_analysis import cli_options
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.command import Command, command_settings

__all__ = ["COMMANDS"]


def _add_events(p: argparse.ArgumentParser) -> None:
    """The ``events`` subcommand's arguments."""
    p.add_argument("c3d", help="C3D file with force platforms and the feet's heel markers")
    p.add_argument("--out", required=True, help="output TSV (side, event, time_s, sample)")
    p.add_argument(
        "--feet",
        nargs=2,
        metavar=("LEFT_HEEL", "RIGHT_HEEL"),
        help="heel marker of each foot (model names, after --label-map; default: events.foot_markers)",
    )
    p.add_argument(
        "--plates", metavar="left=N,right=M", help="belt of each side: a contact on the other foot's plate is flagged"
    )
    cli_options.add_label_map_option(p)
    cli_options.add_rotate_option(p)
    p.add_argument(
        "--threshold-on-n",
        type=float,
        help="heel strike: force over rest rises through (N; default: events.threshold_on_n)",
    )
    p.add_argument(
        "--threshold-off-n",
        type=float,
        help="toe-off: force over rest falls through (N; default: events.threshold_off_n)",
    )
    cli_options.add_configfile_option(p)


def _plates(text: str | None) -> dict[str, int] | None:
    """``left=1,right=2`` -> {"left": 1, "right": 2}."""
    if text is None:
        return None
    out = {}
    for item in text.split(","):
        side, _, number = item.partition("=")
        try:
            out[side.strip()] = int(number)
        except ValueError:
            raise LoperInputError(f"--plates: expected SIDE=N[,SIDE=N] such as left=1,right=2, got {text!r}") from None
    return out


def _events(args: argparse.Namespace) -> None:
    from loper_analysis.stages.events.step import EventSettings, events

    settings = command_settings(
        args,
        "events",
        EventSettings(),
        "events",
        threshold_on_n=args.threshold_on_n,
        threshold_off_n=args.threshold_off_n,
        foot_markers=None if args.feet is None else dict(zip(("left", "right"), args.feet)),
        plate_sides=_plates(args.plates),
        rotation_deg=cli_options.rotation_option(args, args.c3d),
        label_map=cli_options.label_map(args.label_map),
    )
    table = events(args.c3d, args.out, settings)
    flagged = table.attrs.get("n_contacts_flagged", 0)
    print(f"{args.out}: {len(table)} events; {flagged} contact(s) flagged and left out")


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="events",
        help="heel strikes and toe-offs from the force platforms -> TSV",
        add_arguments=_add_events,
        run=_events,
        option_keys={
            "threshold_on_n": ("config", ("events", "threshold_on_n")),
            "threshold_off_n": ("config", ("events", "threshold_off_n")),
            "rotate_deg": ("config", ("markers", "lab_to_model_rotation_deg")),
        },
    ),
)
