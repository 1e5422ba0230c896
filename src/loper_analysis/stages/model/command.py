"""The model stage's subcommands: ``scale`` (a generic model scaled to a static trial) and ``segments`` (the swing
leg's segment table)."""

from __future__ import annotations

import argparse
import dataclasses
import tempfile
from pathlib import Path

from loper_analysis import cli_options
from loper_analysis.errors import LoperInputError
from loper_analysis.stages.command import Command, command_settings

__all__ = ["COMMANDS"]


def _add_scale(p: argparse.ArgumentParser) -> None:
    """The ``scale`` subcommand's arguments."""
    p.add_argument("--model", required=True, help="generic OpenSim model (.osim)")
    p.add_argument("--setup", required=True, help="OpenSim ScaleTool setup (.xml)")
    p.add_argument("--static", required=True, help="static trial (.c3d or .trc)")
    p.add_argument(
        "--mass-kg",
        type=float,
        help="subject's body mass (kg); default: from the force plates the subject stands on in a .c3d static trial",
    )
    p.add_argument("--out", required=True, help="output scaled model (.osim)")
    p.add_argument(
        "--report", metavar="SCALE.tsv", help="output TSV: scale factors per body and marker errors after scaling"
    )
    p.add_argument(
        "--start",
        type=float,
        help="first time of the static trial to use (s; default: the setup's time range, else the stillest "
        "model.static_duration_s)",
    )
    p.add_argument("--end", type=float, help="last time of the static trial to use (s)")
    p.add_argument(
        "--max-motion-rms-m",
        type=float,
        help="refuse a static trial with a marker moving "
        "more than this (m, RMS about its mean over the window; 0: not checked; default: "
        "model.static_max_motion_rms_m)",
    )
    cli_options.add_label_map_option(p)
    cli_options.add_rotate_option(p)
    p.add_argument("--cutoff-hz", type=float, default=0.0, help="low-pass of a .c3d static trial (Hz); 0: none")
    p.add_argument(
        "--max-gap-frames",
        type=int,
        default=0,
        help="fill gaps of a .c3d static trial up to this "
        "(default 0: each marker is averaged over the frames where it is present)",
    )
    cli_options.add_configfile_option(p)


def _scale(args: argparse.Namespace) -> None:
    from loper_analysis.io.readers import read_label_maps
    from loper_analysis.stages.markers.step import MarkerSettings, markers
    from loper_analysis.stages.model.step import ModelSettings, ScaleFiles, scale_with_setup
    from loper_analysis.stages.settings import stage_settings

    config, line = cli_options.read_config(args)
    print(line)
    settings = ModelSettings() if config is None else stage_settings(config, "model")
    given = {
        "rotation_deg": cli_options.rotation_option(args, args.static),
        "time_range_s": None if args.start is None else (args.start, args.end),
        "max_motion_rms_m": args.max_motion_rms_m,
    }
    settings = dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None})
    if not settings.max_motion_rms_m:
        settings = dataclasses.replace(settings, max_motion_rms_m=None)
    static = c3d = Path(args.static)
    lab_labels = lab_angles = None
    with tempfile.TemporaryDirectory() as tmp:
        if static.suffix.lower() == ".c3d":
            trc = Path(tmp) / (static.stem + ".trc")
            label_map = cli_options.label_map(args.label_map)
            if label_map is None and config is not None:
                label_map = read_label_maps(stage_settings(config, "markers").label_map)
            frame = MarkerSettings(
                rotation_deg=settings.rotation_deg,
                walking_direction="auto" if config is None else stage_settings(config, "markers").walking_direction,
                max_gap_frames=args.max_gap_frames,
                cutoff_hz=args.cutoff_hz or None,
                label_map=label_map,
            )
            lab_angles = Path(tmp) / "lab_angles.tsv"
            gaps = markers(static, trc, None, frame, lab_angles_out=lab_angles)
            lab_labels = {row["marker"]: row["label"] for row in gaps.attrs["per_marker"]}
            static = trc
        elif args.mass_kg is None:
            raise LoperInputError(f"scale: {args.static}: a .trc static trial has no force plates: give --mass-kg")
        files = ScaleFiles(
            args.model,
            static,
            args.out,
            setup_xml=args.setup,
            static_c3d=c3d if c3d.suffix.lower() == ".c3d" else None,
            report_out=args.report,
            static_lab_angles=lab_angles,
        )
        try:
            scale_with_setup(files, args.mass_kg, settings, lab_labels=lab_labels)
        except LoperInputError as exc:  # name the file given, not the TRC made from it in a temporary folder
            raise LoperInputError(str(exc).replace(str(static), f"{args.static} (its markers)")) from None
    mass = f"{args.mass_kg:g} kg" if args.mass_kg is not None else "mass from the static trial's force plates"
    print(f"{args.out}: {args.model} scaled with {args.setup} to {args.static} ({mass})")
    if args.report:
        print(
            f"{args.report}: scale factors, marker errors before and after marker placement, the static pose"
            " and the checks' warnings"
        )


def _add_segments(p: argparse.ArgumentParser) -> None:
    """The ``segments`` subcommand's arguments."""
    p.add_argument("--model", help="scaled OpenSim model (.osim): gait2392, Rajagopal2016 or the generated model")
    p.add_argument(
        "--side", choices=("left", "right"), help="the swing leg (with --model; default: study.perturbed_side)"
    )
    p.add_argument("--height-m", type=float, help="without --model: Winter's table from height ...")
    p.add_argument("--mass-kg", type=float, help="... and body mass")
    p.add_argument(
        "--attachment-fraction",
        type=float,
        help="brace position along the thigh (fraction of its length; a model's brace markers win; default: "
        "model.brace_attachment_fraction)",
    )
    p.add_argument("--out", required=True, help="output TSV")
    cli_options.add_configfile_option(p)


def _segments(args: argparse.Namespace) -> None:
    from loper_analysis.stages.model.step import ModelSettings, anthropometric_segments, segments_from_model_file

    if args.model is not None:
        if args.height_m is not None or args.mass_kg is not None:
            raise LoperInputError("segments: give either --model or --height-m and --mass-kg, not both")
    elif args.height_m is None or args.mass_kg is None:
        raise LoperInputError("segments: give --model SCALED.osim, or --height-m and --mass-kg")
    settings = command_settings(
        args, "model", ModelSettings(), side=args.side, attachment_fraction=args.attachment_fraction
    )
    if args.model is not None:
        segments_from_model_file(args.model, args.out, settings)
    else:
        anthropometric_segments(args.out, args.height_m, args.mass_kg, settings.attachment_fraction)
    print(f"{args.out}: segment table")


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="scale",
        help="scale a generic model with a lab's ScaleTool setup and a static trial",
        add_arguments=_add_scale,
        run=_scale,
        option_keys={
            "rotate_deg": ("config", ("markers", "lab_to_model_rotation_deg")),
            "mass_kg": ("subjects", ("mass_kg",)),
            "max_motion_rms_m": ("config", ("model", "static_max_motion_rms_m")),
            "cutoff_hz": ("config", ("markers", "filter", "cutoff_hz")),
            "max_gap_frames": ("config", ("markers", "max_gap_frames")),
        },
        off_with_zero=frozenset({"cutoff_hz", "max_motion_rms_m"}),
    ),
    Command(
        name="segments",
        help="segment table (TSV) from a scaled model, or from height and mass",
        add_arguments=_add_segments,
        run=_segments,
        option_keys={
            "mass_kg": ("subjects", ("mass_kg",)),
            "height_m": ("subjects", ("height_m",)),
            "attachment_fraction": ("config", ("model", "brace_attachment_fraction")),
        },
    ),
)
