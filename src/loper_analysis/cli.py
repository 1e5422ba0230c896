"""The ``loper-analysis`` command: library steps for use outside the workflow.

Subcommands
-----------
segments     write the swing-leg segment table of a subject from height and mass
validate     run (part of) the validation study and write its tables
ik           OpenSim inverse kinematics of a marker file (.c3d or .trc) to a .mot
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from .errors import LoperInputError

__all__ = ["main"]


def _segments(args: argparse.Namespace) -> None:
    from .steps.model import anthropometric_segments

    anthropometric_segments(args.out, args.height_m, args.mass_kg, args.attachment_fraction)


def _validate(args: argparse.Namespace) -> None:
    from .steps.validation import validation_chunk

    validation_chunk(args.segments, {"n_starts": args.n_starts, "seed": args.seed}, args.chunk, args.n_chunks,
                     args.errors, args.fits)


def _ik(args: argparse.Namespace) -> None:
    from .steps.ik import ik_file

    result = ik_file(args.model, args.markers, args.out, args.tasks, args.start, args.end, args.rotate_deg,
                     args.accuracy)
    print(
        f"{args.out}: {len(result.time_s)} frames, marker error RMS {1e3 * np.nanmean(result.marker_rms_m):.2f} mm "
        f"(max {1e3 * np.nanmax(result.marker_max_m):.2f} mm)"
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="loper-analysis", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("segments", help="segment table (TSV) from height and mass (Winter's table)")
    p.add_argument("--height-m", type=float, required=True)
    p.add_argument("--mass-kg", type=float, required=True)
    p.add_argument("--attachment-fraction", type=float, default=0.8, help="brace position along the thigh")
    p.add_argument("--out", required=True, help="output TSV")
    p.set_defaults(func=_segments)
    p = sub.add_parser("validate", help="one chunk of the validation study (the study's design)")
    p.add_argument("--segments", required=True, help="segment table TSV")
    p.add_argument("--chunk", type=int, default=0)
    p.add_argument("--n-chunks", type=int, default=1)
    p.add_argument("--n-starts", type=int, default=10)
    p.add_argument("--seed", type=int, default=2024)
    p.add_argument("--errors", required=True, help="output TSV, one row per combination x condition x parameter")
    p.add_argument("--fits", required=True, help="output TSV, one row per combination x condition")
    p.set_defaults(func=_validate)
    p = sub.add_parser("ik", help="OpenSim inverse kinematics of a .c3d or .trc marker file to a .mot (degrees)")
    p.add_argument("--model", required=True, help="OpenSim model (.osim)")
    p.add_argument("--markers", required=True, help="marker file: .c3d (units from POINT:UNITS) or .trc (Units header)")
    p.add_argument("--out", required=True, help="output .mot (angles in degrees, OpenSim's convention)")
    p.add_argument("--tasks", help="OpenSim IK task-set XML or TSV (name, kind, weight[, value]); default: every "
                   "model marker found in the file, weight 1")
    p.add_argument("--start", type=float, help="first time (s) to solve")
    p.add_argument("--end", type=float, help="last time (s) to solve")
    p.add_argument("--rotate-deg", type=float, nargs=3, metavar=("X", "Y", "Z"),
                   help="rotate the markers about the fixed X, Y, Z axes (degrees) into the model frame; default "
                   "-90 0 0 for .c3d (Qualisys Z-up -> OpenSim Y-up), 0 0 0 for .trc")
    p.add_argument("--accuracy", type=float, default=1e-6, help="IK solver accuracy (OpenSim's default 1e-5)")
    p.set_defaults(func=_ik)
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except LoperInputError as exc:
        print(f"loper-analysis {args.command}: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
