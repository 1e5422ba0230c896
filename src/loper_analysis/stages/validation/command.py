"""The validation stage's subcommand: ``validate``, one chunk of the validation study."""

from __future__ import annotations

import argparse
import dataclasses

from loper_analysis import cli_options
from loper_analysis.stages.command import Command

__all__ = ["COMMANDS"]


def _add_validate(p: argparse.ArgumentParser) -> None:
    """The ``validate`` subcommand's arguments."""
    cli_options.add_configfile_option(p)
    p.add_argument("--segments", required=True, help="segment table TSV")
    p.add_argument("--chunk", type=int, default=0)
    p.add_argument("--n-chunks", type=int, help="chunks of the study (default: validation.n_chunks of the config)")
    p.add_argument("--n-starts", type=int, help="multistart starts (default: impedance.n_starts)")
    p.add_argument("--seed", type=int, help="seed (default: the config's seed)")
    p.add_argument("--errors", required=True, help="output TSV, one row per combination x condition x parameter")
    p.add_argument("--fits", required=True, help="output TSV, one row per combination x condition")


def _validate(args: argparse.Namespace) -> None:
    from loper_analysis.impedance.identification.validation import ValidationSettings
    from loper_analysis.stages.settings import stage_settings
    from loper_analysis.stages.validation.step import validation_chunk

    config, line = cli_options.read_config(args)
    print(line)
    settings = ValidationSettings() if config is None else stage_settings(config, "validation")
    given = {k: v for k, v in (("n_starts", args.n_starts), ("seed", args.seed)) if v is not None}
    settings = dataclasses.replace(settings, **given)
    n_chunks = args.n_chunks if args.n_chunks is not None else (config or {}).get("validation", {}).get("n_chunks", 1)
    validation_chunk(args.segments, settings, args.chunk, n_chunks, args.errors, args.fits)


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="validate",
        help="one chunk of the validation study (the study's design)",
        description="Simulate and identify one chunk of the validation study with the settings of the workflow's "
        "validation rules: config/config.yaml of the working directory with each --configfile over it "
        "(validation.*, impedance.*, seed); options given here win; without any config file the "
        "library's defaults (said in the first line printed).",
        add_arguments=_add_validate,
        run=_validate,
        option_keys={
            "n_starts": ("config", ("impedance", "n_starts")),
            "n_chunks": ("config", ("validation", "n_chunks")),
            "seed": ("config", ("seed",)),
        },
    ),
)
