"""The ``loper-analysis`` command: library steps for use outside the workflow.

Subcommands
-----------
segments     write the swing-leg segment table of a subject from height and mass
validate     run (part of) the validation study and write its tables
"""

from __future__ import annotations

import argparse
import sys

from .errors import LoperInputError

__all__ = ["main"]


def _segments(args: argparse.Namespace) -> None:
    from .dynamics import segment_parameters_from_anthropometry

    segment_parameters_from_anthropometry(args.height_m, args.mass_kg, args.attachment_fraction).to_tsv(args.out)


def _validate(args: argparse.Namespace) -> None:
    from .validation import ValidationSettings, validation_chunk_tables

    settings = ValidationSettings(n_starts=args.n_starts, seed=args.seed)
    validation_chunk_tables(args.segments, settings, args.chunk, args.n_chunks, args.errors, args.fits)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="loper-analysis", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("segments", help="segment table (TSV) from height and mass (Winter's table)")
    p.add_argument("--height-m", type=float, required=True)
    p.add_argument("--mass-kg", type=float, required=True)
    p.add_argument("--attachment-fraction", type=float, default=0.8, help="brace position along the thigh")
    p.add_argument("--out", required=True, help="output TSV")
    p.set_defaults(func=_segments)
    p = sub.add_parser("validate", help="one chunk of the validation study (defaults of DESIGN.md)")
    p.add_argument("--segments", required=True, help="segment table TSV")
    p.add_argument("--chunk", type=int, default=0)
    p.add_argument("--n-chunks", type=int, default=1)
    p.add_argument("--n-starts", type=int, default=10)
    p.add_argument("--seed", type=int, default=2024)
    p.add_argument("--errors", required=True, help="output TSV, one row per combination x condition x parameter")
    p.add_argument("--fits", required=True, help="output TSV, one row per combination x condition")
    p.set_defaults(func=_validate)
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except LoperInputError as exc:
        print(f"loper-analysis {args.command}: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
