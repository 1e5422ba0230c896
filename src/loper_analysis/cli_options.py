"""The options several ``loper-analysis`` subcommands share: their arguments, and what the handlers make of them.

The ``add_*`` functions add an option to a subcommand's parser; the others
turn the parsed options into what a stage takes (a rotation, a walking
direction, a label map) and read the configuration the workflow run here would
see (:func:`read_config`, :func:`stage_settings`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = [
    "add_configfile_option",
    "add_label_map_option",
    "add_rotate_option",
    "label_map",
    "read_config",
    "rotation_option",
    "walking_direction",
]


def add_rotate_option(p: argparse.ArgumentParser, heading: bool = False) -> None:
    """``--rotate-deg`` (and with ``heading`` ``--walking-direction``)."""
    p.add_argument(
        "--rotate-deg",
        type=float,
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="rotate lab coordinates about the fixed X, Y, Z axes (degrees) into the model frame; default "
        "for .c3d: markers.lab_to_model_rotation_deg (without a config -90 0 0, Qualisys Z-up -> OpenSim Y-up); "
        "0 0 0 for .trc",
    )
    if heading:
        p.add_argument(
            "--walking-direction",
            choices=("auto", "fixed"),
            help="auto: a trial that travels (overground) is turned by quarter turns about the vertical to "
            "walk along the model's +X; fixed: the rotation as it is (default: fixed with --rotate-deg, "
            "else markers.walking_direction, without a config auto)",
        )


def add_label_map_option(p: argparse.ArgumentParser) -> None:
    """``--label-map``: the lab's labels -> the model's markers."""
    p.add_argument(
        "--label-map",
        metavar="MAP",
        help="TSV (columns label, marker) or YAML mapping: lab label -> "
        "model marker; subject prefixes (Name:) are stripped first (default for a .c3d: markers.label_map)",
    )


def add_configfile_option(p: argparse.ArgumentParser) -> None:
    """``--configfile``: config files layered over ``config/config.yaml``."""
    p.add_argument(
        "--configfile",
        nargs="+",
        metavar="FILE",
        help="config file(s) layered over config/config.yaml "
        "of the working directory (when present), each over the ones before, as snakemake --configfile "
        "does; default: config/config.yaml alone",
    )


def rotation_option(args: argparse.Namespace, path: str) -> tuple[float, float, float] | None:
    """--rotate-deg, else None for a C3D (the config's ``markers.lab_to_model_rotation_deg`` serves) and 0 0 0 for
    anything else."""
    if args.rotate_deg is not None or str(path).lower().endswith(".c3d"):
        return None if args.rotate_deg is None else tuple(args.rotate_deg)
    return (0.0, 0.0, 0.0)


def walking_direction(args: argparse.Namespace) -> str:
    """--walking-direction, else ``fixed`` when --rotate-deg is given (the rotation as typed), else None (the
    config's ``markers.walking_direction``)."""
    if args.walking_direction is not None:
        return args.walking_direction
    return "fixed" if args.rotate_deg is not None else None


def label_map(path: str | None) -> dict[str, str] | None:
    """The label map of ``--label-map`` (None when not given)."""
    from loper_analysis.io.readers import read_label_map

    return None if path is None else read_label_map(path)


def read_config(args: argparse.Namespace) -> tuple[dict | None, str]:
    """The configuration as the workflow run here would see it, and one line saying which file(s) it came from.

    ``config/config.yaml`` of the working directory when present (the
    Snakefile's own config file), then each ``--configfile`` over it, as
    Snakemake layers them (:func:`loper_analysis.config_file.load_config`); a
    file named twice counts where it was named last. None (and a line saying
    so) when there is neither: the library's defaults serve.
    """
    from loper_analysis.config_file import DEFAULT_CONFIG, load_config

    named = ([DEFAULT_CONFIG] if DEFAULT_CONFIG.is_file() else []) + [Path(f) for f in args.configfile or []]
    last = {p.resolve(): n for n, p in enumerate(named)}
    files = [p for n, p in enumerate(named) if last[p.resolve()] == n]
    if not files:
        return None, (
            f"config: none (no {DEFAULT_CONFIG.as_posix()} in {Path.cwd()} and no --configfile): library "
            "defaults, which may differ from the workflow's settings"
        )
    config, used = load_config(files)
    order = " (later files override earlier ones)" if len(used) > 1 else ""
    return config, f"config: {', '.join(used)}{order}"
