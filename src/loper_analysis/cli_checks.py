"""Checks of a ``loper-analysis`` command line before any work: no output over an input, every option within the
limits of its config key.

:func:`refuse_overwriting` compares the files a command reads with those it writes (the same path, a link or a
hard link); :func:`check_option_limits` holds each option with a config counterpart to that key's range, type and
enumeration in the workflow's schema (:data:`OPTION_KEYS`), so the command and the workflow accept the same values,
and refuses every numeric option that is NaN or infinite (:func:`refuse_non_finite_options`).
:func:`refuse_config_code` reads the config files ``report`` passes on to Snakemake before Snakemake does, whose
loader would run a YTE template as Python.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Sequence
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.stages.command import stage_commands

__all__ = [
    "OPTION_KEYS",
    "check_option_limits",
    "refuse_config_code",
    "refuse_non_finite_options",
    "refuse_overwriting",
]

#: Options naming a file a subcommand reads, and those naming a file it writes.
_INPUT_OPTIONS: tuple[str, ...] = ("c3d", "model", "setup", "static", "markers", "segments", "tasks", "label_map",
                                   "marker_set", "configfile")  # fmt: skip
_OUTPUT_OPTIONS: tuple[str, ...] = ("out", "gaps", "report", "errors", "fits", "label_map_out", "config_out", "target")


def _files(args: argparse.Namespace, names: Sequence[str]) -> list[tuple[str, Path]]:
    """(option, path) of every file the options name (lists flattened)."""
    out = []
    for name in names:
        value = getattr(args, name, None)
        for item in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(item, (str, Path)) and str(item):
                out.append(("--" + name.replace("_", "-") if name not in ("c3d", "target") else name, Path(item)))
    return out


def _same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (the same path, a link to it, or a hard link)."""
    if a.exists() and b.exists():
        return os.path.samefile(a, b)
    return a.resolve() == b.resolve()


def refuse_overwriting(args: argparse.Namespace) -> None:
    """Stop before any work when a subcommand would write over one of its inputs, or write two outputs to one file.

    Raises
    ------
    LoperInputError
        Naming the output option and the input (or other output) option and their paths.
    """
    inputs, outputs = _files(args, _INPUT_OPTIONS), _files(args, _OUTPUT_OPTIONS)
    for k, (out_name, out_path) in enumerate(outputs):
        for in_name, in_path in inputs + outputs[:k]:
            if _same_file(out_path, in_path):
                raise LoperInputError(
                    f"{out_path}: {out_name} would write over {in_name} {in_path}: nothing was done; give another "
                    "output path"
                )


#: Each command's options with a config counterpart: option -> (schema file, key path), from the stages' commands
#: (:attr:`loper_analysis.stages.command.Command.option_keys`); a value is held to the key's limits
#: (:func:`check_option_limits`). ``subjects`` is the subject sheet's schema.
OPTION_KEYS: dict[str, dict[str, tuple[str, tuple[str, ...]]]] = {
    c.name: dict(c.option_keys) for c in stage_commands() if c.option_keys
}
#: Options whose 0 switches their step off (their help says so), beside the key's limits.
_OFF_WITH_ZERO: set[tuple[str, str]] = {(c.name, o) for c in stage_commands() for o in c.off_with_zero}


def refuse_config_code(args: argparse.Namespace) -> None:
    """Refuse, before Snakemake is started, a config file ``report`` passes on with ``--configfile`` that holds a YTE
    template, a Python tag or an alias bomb (:func:`loper_analysis.schema.check_yaml_file`): Snakemake renders a
    template while it reads its command line, before the workflow's own check.

    Raises
    ------
    LoperInputError
        Naming the file, the place and the construct.
    """
    if args.command != "report":
        return
    from loper_analysis.schema import check_yaml_file
    from loper_analysis.stages.report.step import configfiles_given

    for path in configfiles_given(getattr(args, "snakemake_args", None) or []):
        if Path(path).is_file():  # a missing file: Snakemake's own message
            check_yaml_file(path)


def refuse_non_finite_options(args: argparse.Namespace) -> None:
    """Refuse every numeric option given as ``nan``, ``inf`` or ``-inf`` (Python's ``float`` reads them as numbers,
    and a limit lets NaN through: every comparison with it is false), whether or not it has a config key.

    Raises
    ------
    LoperInputError
        Naming the option and its value.
    """
    from loper_analysis.schema import refuse_non_finite_option

    for attr, value in vars(args).items():
        refuse_non_finite_option(value, "--" + attr.replace("_", "-"))


def check_option_limits(args: argparse.Namespace) -> None:
    """Hold every option given to the limits of its config key (one schema for the workflow and the command), and
    every numeric option to a finite number (:func:`refuse_non_finite_options`).

    Raises
    ------
    LoperInputError
        Naming the option, its value, the problem and the key.
    """
    from loper_analysis.config_file import find_schema
    from loper_analysis.schema import check_value

    refuse_non_finite_options(args)
    keys = OPTION_KEYS.get(args.command, {})
    given = {a: getattr(args, a) for a in keys if getattr(args, a, None) is not None}
    given = {a: v for a, v in given.items() if not ((args.command, a) in _OFF_WITH_ZERO and v == 0)}
    if not given:
        return
    files = getattr(args, "configfile", None) or []
    schemas = {"config": find_schema(files), "subjects": find_schema(files, "subjects.schema.yaml")}
    for attr, value in given.items():
        schema, key_path = keys[attr]
        check_value(value, schemas[schema], key_path, "--" + attr.replace("_", "-"))
