"""The report stage's subcommand: ``report``, the Snakemake report written whole or not at all."""

from __future__ import annotations

import argparse

from loper_analysis.stages.command import Command

__all__ = ["COMMANDS"]


def _add_report(p: argparse.ArgumentParser) -> None:
    """The ``report`` subcommand's arguments."""
    p.add_argument("target", help="the report: .html (one self-contained file) or .zip, e.g. results/report.html")
    p.add_argument(
        "snakemake_args",
        nargs=argparse.REMAINDER,
        metavar="SNAKEMAKE_ARGS",
        help="passed on to snakemake after --report, e.g. --configfile my.yaml",
    )


def _report(args: argparse.Namespace) -> None:
    from loper_analysis.stages.report.step import write_report

    target = write_report(args.target, snakemake_args=args.snakemake_args)
    print(f"{target}: report written ({target.stat().st_size / 1e6:.1f} MB)")


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="report",
        help="the Snakemake report, written beside its target and moved over it when whole",
        description="Run `snakemake --report` (this Python's Snakemake) into a temporary file beside "
        "TARGET, check that it is complete (an HTML report ends with </html>) and move it over "
        "TARGET; on any failure the previous report stays as it was.",
        add_arguments=_add_report,
        run=_report,
    ),
)
