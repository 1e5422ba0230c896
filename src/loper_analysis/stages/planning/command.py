"""The planning stage's subcommand: ``plan``, the predicted precision of a planned experiment from a pilot subject.

:func:`plan_settings` and :func:`plan_pilot` read the planner's settings and its pilot from the options and the
config, as the workflow's rule ``planning`` does.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
from typing import TYPE_CHECKING

from loper_analysis import cli_options
from loper_analysis.errors import LoperInputError
from loper_analysis.stages import study_paths
from loper_analysis.stages.command import Command
from loper_analysis.stages.settings import stage_settings

if TYPE_CHECKING:
    from loper_analysis.layout import Paths

__all__ = ["COMMANDS", "plan_pilot", "plan_settings"]


def _add_design_options(p: argparse.ArgumentParser) -> None:
    """The options of the planned design beyond the thigh rod's pulse: a second rod at the shank, couplings."""
    p.add_argument(
        "--shank-force-n",
        type=float,
        help="a second rod just above the ankle, pushed with the thigh: its pulse (N; default: "
        "planning.shank_pulse_force_n, else 0: the thigh rod alone)",
    )
    p.add_argument(
        "--shank-attachment-fraction",
        type=float,
        help="that rod's point on the shank, as a fraction of the shank's length from the knee (default: "
        "device.shank_rod.attachment_fraction, else 0.85)",
    )
    p.add_argument(
        "--couplings",
        nargs="*",
        choices=("hip_knee", "knee_ankle"),
        help="inter-joint (bi-articular) stiffnesses to plan beside the six, planned at 0: the plan says whether the "
        "design identifies each (default: impedance.couplings, else none)",
    )
    p.add_argument(
        "--shank-direction-deg",
        type=float,
        help="that rod's push: the shank's forward normal turned toward the ankle by this angle (deg; default: "
        "device.shank_rod.direction_deg, else 0)",
    )


def _add_plan(p: argparse.ArgumentParser) -> None:
    """The ``plan`` subcommand's arguments."""
    from loper_analysis.layout import RESULTS_DIR

    cli_options.add_configfile_option(p)
    p.add_argument("--results", default=RESULTS_DIR, help="results folder of the pilot's processed trials")
    p.add_argument("--subject", help="pilot subject (default: planning.pilot_subject, else the first of --subjects)")
    p.add_argument(
        "--subjects",
        help="subject sheet whose first subject is the default (default: the config's "
        "subjects, else config/subjects.tsv)",
    )
    p.add_argument(
        "--trials",
        nargs="+",
        help="the pilot's trials walked with the device (default: every angle "
        "table in RESULTS/ik/SUBJECT but --exclude-trials)",
    )
    p.add_argument(
        "--exclude-trials", nargs="*", help="trials without the device (default: study.no_device, else walk-nodevice)"
    )
    p.add_argument("--segments", help="segment table of the subject to plan for (default: the pilot's)")
    p.add_argument(
        "--impedance",
        nargs="+",
        help="impedance rows giving the planned impedance (default: RESULTS/impedance/SUBJECT/NNN.tsv)",
    )
    p.add_argument(
        "--impedance-values",
        type=float,
        nargs=6,
        metavar=("K_HIP", "D_HIP", "K_KNEE", "D_KNEE", "K_ANKLE", "D_ANKLE"),
        help="planned impedance (N·m/rad, N·m·s/rad) instead of the pilot's fits",
    )
    p.add_argument(
        "--onset-ms",
        type=float,
        nargs="+",
        help="onsets after toe-off (ms; default: study.perturbation_onsets_ms, else those of the impedance rows)",
    )
    p.add_argument(
        "--strides", type=int, nargs="+", help="perturbed strides averaged (default: planning.strides, else 10 20 40)"
    )
    p.add_argument("--force-n", type=float, help="pulse: desired force (N; default: planning.pulse_force_n, else 40)")
    p.add_argument("--duration-s", type=float, help="pulse duration (s; default: planning.pulse_duration_s, else 0.1)")
    _add_design_options(p)
    p.add_argument(
        "--target",
        nargs=3,
        action="append",
        metavar=("JOINT", "PARAM", "PERCENT"),
        help="strides needed for a 95 %% CI half-width of PERCENT %% of the planned value, e.g. hip D 15 "
        "(targets given here replace planning.targets)",
    )
    p.add_argument(
        "--target-half-width",
        nargs=3,
        action="append",
        metavar=("JOINT", "PARAM", "VALUE"),
        help="strides needed for an absolute half-width (N·m/rad or N·m·s/rad)",
    )
    p.add_argument("--out", help="output TSV (one row per onset x joint x parameter x stride count)")


def _first_subject(subjects_tsv: str, paths: Paths) -> str:
    """The first subject of the subject sheet, else the first subject with joint angles under ``results/ik``."""
    sheet = Path(subjects_tsv)
    if sheet.is_file():
        import pandas as pd

        from loper_analysis.io.readers import read_subject_sheet

        names = read_subject_sheet(sheet).get("subject", pd.Series(dtype=str))
        if len(names):
            return str(names.iloc[0])
    ik = Path(paths.ik.root)
    found = sorted(p.name for p in ik.glob("*") if p.is_dir())
    if not found:
        raise LoperInputError(f"plan: no subject given, {sheet} not found and no subject under {ik}")
    return found[0]


def plan_settings(args: argparse.Namespace, config: dict | None):
    """The planner's settings: those of the rule ``planning`` (the config's,
    :func:`loper_analysis.stages.planning.settings.read_settings`), else the library's defaults; then the
    options given on the command line (targets given replace the config's).
    """
    from loper_analysis.stages.planning.step import PlanningSettings
    from loper_analysis.stages.settings import stage_settings

    settings = PlanningSettings() if config is None else stage_settings(config, "planning")
    options = (
        ("pulse_force_n", args.force_n),
        ("pulse_duration_s", args.duration_s),
        ("shank_pulse_force_n", args.shank_force_n),
    )
    pulse = {k: v for k, v in options if v is not None}
    rod = {
        k: v
        for k, v in (
            ("attachment_fraction", args.shank_attachment_fraction),
            ("direction_rad", None if args.shank_direction_deg is None else math.radians(args.shank_direction_deg)),
        )
        if v is not None
    }
    if rod:
        pulse["shank_rod"] = dataclasses.replace(settings.plan.shank_rod, **rod)
    if args.couplings is not None:
        pulse["couplings"] = tuple(args.couplings)
    given = {
        "onsets_ms": None if args.onset_ms is None else tuple(args.onset_ms),
        "strides": None if args.strides is None else tuple(args.strides),
        "plan": dataclasses.replace(settings.plan, **pulse) if pulse else None,
    }
    if args.target is not None or args.target_half_width is not None:
        given["targets"] = tuple(
            [{"joint": j, "parameter": p, "percent": float(v)} for j, p, v in args.target or []]
            + [{"joint": j, "parameter": p, "half_width": float(v)} for j, p, v in args.target_half_width or []]
        )
    return dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None})


def plan_pilot(args: argparse.Namespace, config: dict | None) -> tuple[str | None, str, list[str]]:
    """The pilot subject (``--subject``, else ``planning.pilot_subject``; None: the first of the subject sheet),
    the subject sheet (``--subjects``, else the config's ``subjects``, else ``config/subjects.tsv``) and the
    trials without the device (``--exclude-trials``, else ``study.no_device``, else the library's)."""
    from loper_analysis.study_design import StudyDesign

    study = None if config is None else stage_settings(config, "study")
    pilot = args.subject or (None if config is None else stage_settings(config, "planning").pilot_subject)
    sheet = args.subjects or ("config/subjects.tsv" if study is None else study.subjects)
    exclude = args.exclude_trials
    if exclude is None:
        exclude = [StudyDesign().no_device if study is None else study.design.no_device]
    return pilot, sheet, exclude


def _plan(args: argparse.Namespace) -> None:
    from loper_analysis.layout import fill
    from loper_analysis.planning.precision import PLAN_COLUMNS
    from loper_analysis.stages.planning.files import PilotFiles, PilotTrial
    from loper_analysis.stages.planning.step import plan

    config, line = cli_options.read_config(args)
    print(line)
    settings = plan_settings(args, config)
    pilot, sheet, exclude = plan_pilot(args, config)
    paths = study_paths(results_dir=args.results)
    subject = pilot or _first_subject(sheet, paths)
    angles = Path(fill(paths.ik.angles, subject=subject))
    suffix = angles.name.format(trial="")  # ".angles.tsv"
    names = args.trials or sorted(p.name.removesuffix(suffix) for p in angles.parent.glob(f"*{suffix}"))
    names = [n for n in names if n not in exclude]
    if not names:
        raise LoperInputError(
            f"plan: no joint-angle table of a trial with the device in {angles.parent} (excluded: {', '.join(exclude)})"
        )
    trials = {
        n: PilotTrial(
            angles=Path(fill(paths.ik.angles, subject=subject, trial=n)),
            strides=Path(fill(paths.strides.strides, subject=subject, trial=n)),
        )
        for n in names
    }
    for path in [*(t.angles for t in trials.values()), *(t.strides for t in trials.values())]:
        if not path.is_file():
            raise LoperInputError(f"plan: {path} not found")
    segments = Path(args.segments) if args.segments else Path(fill(paths.model.segments, subject=subject))
    fits = Path(fill(paths.impedance.fit, subject=subject))
    impedance_tsvs = (
        [Path(f) for f in args.impedance]
        if args.impedance
        else sorted(fits.parent.glob(fits.name.format(onset="[0-9][0-9][0-9]")))
    )
    values = args.impedance_values
    if settings.onsets_ms is None:
        if values is not None:
            raise LoperInputError("plan: with --impedance-values give --onset-ms")
        onsets = [int(p.stem) for p in impedance_tsvs if p.stem.isdigit()]
        if not onsets:
            raise LoperInputError(
                f"plan: no impedance rows of {subject} in {fits.parent}; "
                "give --onset-ms and --impedance or --impedance-values"
            )
        settings = dataclasses.replace(settings, onsets_ms=tuple(onsets))
    files = PilotFiles(trials=trials, segments=segments, impedance=tuple(impedance_tsvs))
    table, answers = plan(files, subject, settings, args.out, impedance=values)
    shown = table[list(PLAN_COLUMNS[PLAN_COLUMNS.index("onset_ms") : PLAN_COLUMNS.index("ci95_half_width_pct") + 1])]
    print(
        f"pilot {subject} ({len(names)} trials with the device; {settings.response.counterfactual.replace('_', ' ')} "
        "counterfactual; null pairs: "
        f"{', '.join(str(n) for n in table.groupby('onset_ms')['n_null_pairs'].first())}; perturbed pairs: "
        f"{', '.join(str(n) for n in table.groupby('onset_ms')['n_perturbed_pairs'].first())}); "
        f"pulse {settings.plan.pulse_force_n:g} N for {settings.plan.pulse_duration_s:g} s"
    )
    print(shown.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    for a in answers:
        print(a)
    if args.out:
        print(f"{args.out}: {len(table)} rows")


#: The stage's subcommands.
COMMANDS: tuple[Command, ...] = (
    Command(
        name="plan",
        help="predicted 95 %% CI half-width of K and D for a planned experiment (pilot subject)",
        description="Predict the 95 % CI half-width of K and D of a planned experiment from a pilot "
        "subject's processed trials, with the settings of the workflow's rule 'planning'. Settings, "
        "highest priority first: (1) options given here; (2) the config: config/config.yaml of the "
        "working directory with each --configfile over it, as Snakemake layers them (onsets: "
        "study.perturbation_onsets_ms; strides, targets, pulse and pilot: planning.*; fit window, "
        "initial state, bounds, null pairs and the counterfactual planned for: impedance.*; outliers: "
        "strides.iqr_whisker, "
        "strides.max_outlier_fraction; device: device.parameters; excluded trial: study.no_device; "
        "subject sheet: subjects); (3) without any config file, the library's defaults (said in the "
        "first line printed, which names the config file(s) used).",
        add_arguments=_add_plan,
        run=_plan,
        option_keys={
            "force_n": ("config", ("planning", "pulse_force_n")),
            "duration_s": ("config", ("planning", "pulse_duration_s")),
            "shank_force_n": ("config", ("planning", "shank_pulse_force_n")),
            "shank_attachment_fraction": ("config", ("device", "shank_rod", "attachment_fraction")),
            "shank_direction_deg": ("config", ("device", "shank_rod", "direction_deg")),
            "strides": ("config", ("planning", "strides")),
        },
    ),
)
