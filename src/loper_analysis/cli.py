"""The ``loper-analysis`` command: each stage of the pipeline on one file, with the functions the rules call.

Subcommands
-----------
markers      C3D markers -> label map, gap fill, lab -> model frame, low-pass -> TRC (mm)
grf          C3D force platforms -> OpenSim external-loads .mot (model frame)
events       heel strikes and toe-offs from the force platforms (or named GRF channels) -> events TSV
scale        scale a generic OpenSim model with a lab's ScaleTool setup and a static trial
segments     swing-leg segment table from a scaled model, or from height and mass (Winter's table)
ik           OpenSim inverse kinematics of a marker file (.c3d or .trc) to a .mot
validate     run (part of) the validation study and write its tables
plan         predict the 95 % CI half-width of K and D of a planned experiment from a pilot subject
inspect      what a lab's C3D files hold; a subject's config from a marker-set template (or labels matched to a model)
report       the Snakemake report (``snakemake --report``) written beside its target and moved over it when whole

Every command exits with 0 on success and with 2 and one line on standard
error naming the file and the cause when an input cannot serve
(``--traceback`` shows Python's traceback instead, for bug reports).
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.cli_checks import check_option_limits, refuse_config_code, refuse_overwriting
from loper_analysis.cli_parser import build_parser
from loper_analysis.errors import LoperInputError, one_line
from loper_analysis.layout import Paths, fill

__all__ = ["command_parser", "main"]


def _rotation_option(args: argparse.Namespace, path: str) -> tuple[float, float, float] | None:
    """--rotate-deg, else None for a C3D (the config's ``markers.lab_to_model_rotation_deg`` serves) and 0 0 0 for
    anything else."""
    if args.rotate_deg is not None or str(path).lower().endswith(".c3d"):
        return None if args.rotate_deg is None else tuple(args.rotate_deg)
    return (0.0, 0.0, 0.0)


def _walking_direction(args: argparse.Namespace) -> str:
    """--walking-direction, else ``fixed`` when --rotate-deg is given (the rotation as typed), else None (the
    config's ``markers.walking_direction``)."""
    if args.walking_direction is not None:
        return args.walking_direction
    return "fixed" if args.rotate_deg is not None else None


def _label_map(path: str | None) -> dict[str, str] | None:
    from loper_analysis.io.readers import read_label_map

    return None if path is None else read_label_map(path)


def _stage_settings(args: argparse.Namespace, settings_type, **given):
    """A stage's settings: the config's (:func:`_read_config`, its line printed), else the library's defaults;
    then each option in ``given`` that is not None."""
    config, line = _read_config(args)
    print(line)
    settings = settings_type() if config is None else settings_type.from_config(config)
    if config is not None and "label_map" in given and given["label_map"] is None:
        given["label_map"] = config["markers"]["label_map"] or None
    return dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None})


def _markers(args: argparse.Namespace) -> None:
    from loper_analysis.stages.markers.step import MarkerSettings, markers

    settings = _stage_settings(
        args,
        MarkerSettings,
        rotation_deg=_rotation_option(args, args.c3d),
        walking_direction=_walking_direction(args),
        cutoff_hz=args.cutoff_hz,
        order=args.order,
        max_gap_frames=args.max_gap_frames,
        label_map=_label_map(args.label_map),
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


def _grf(args: argparse.Namespace) -> None:
    from loper_analysis.gait.grf_settings import GRFSettings
    from loper_analysis.stages.grf.step import grf

    settings = _stage_settings(
        args, GRFSettings, rotation_deg=_rotation_option(args, args.c3d), threshold_n=args.threshold_n
    )
    table = grf(args.c3d, args.out, settings)
    n_plates = (table.shape[1] - 1) // 9
    print(f"{args.out}: {len(table)} samples, {n_plates} force platform(s)")


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

    settings = _stage_settings(
        args,
        EventSettings,
        threshold_on_n=args.threshold_on_n,
        threshold_off_n=args.threshold_off_n,
        foot_markers=None if args.feet is None else dict(zip(("left", "right"), args.feet)),
        plate_sides=_plates(args.plates),
        rotation_deg=_rotation_option(args, args.c3d),
        label_map=_label_map(args.label_map),
    )
    table = events(args.c3d, args.out, settings)
    flagged = table.attrs.get("n_contacts_flagged", 0)
    print(f"{args.out}: {len(table)} events; {flagged} contact(s) flagged and left out")


def _scale(args: argparse.Namespace) -> None:
    from loper_analysis.io.readers import read_label_maps
    from loper_analysis.stages.markers.step import MarkerSettings, markers
    from loper_analysis.stages.model.step import ModelSettings, ScaleFiles, scale_with_setup

    config, line = _read_config(args)
    print(line)
    settings = ModelSettings() if config is None else ModelSettings.from_config(config)
    given = {
        "rotation_deg": _rotation_option(args, args.static),
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
            label_map = _label_map(args.label_map)
            if label_map is None and config is not None:
                label_map = read_label_maps(config["markers"]["label_map"] or None)
            frame = MarkerSettings(
                rotation_deg=settings.rotation_deg,
                walking_direction="auto" if config is None else config["markers"]["walking_direction"],
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


def _segments(args: argparse.Namespace) -> None:
    from loper_analysis.stages.model.step import ModelSettings, anthropometric_segments, segments_from_model_file

    if args.model is not None:
        if args.height_m is not None or args.mass_kg is not None:
            raise LoperInputError("segments: give either --model or --height-m and --mass-kg, not both")
    elif args.height_m is None or args.mass_kg is None:
        raise LoperInputError("segments: give --model SCALED.osim, or --height-m and --mass-kg")
    settings = _stage_settings(args, ModelSettings, side=args.side, attachment_fraction=args.attachment_fraction)
    if args.model is not None:
        segments_from_model_file(args.model, args.out, settings)
    else:
        anthropometric_segments(args.out, args.height_m, args.mass_kg, settings.attachment_fraction)
    print(f"{args.out}: segment table")


def _validate(args: argparse.Namespace) -> None:
    from loper_analysis.impedance.identification.validation import ValidationSettings
    from loper_analysis.stages.validation.step import validation_chunk

    config, line = _read_config(args)
    print(line)
    settings = ValidationSettings() if config is None else ValidationSettings.from_config(config)
    given = {k: v for k, v in (("n_starts", args.n_starts), ("seed", args.seed)) if v is not None}
    settings = dataclasses.replace(settings, **given)
    n_chunks = args.n_chunks if args.n_chunks is not None else (config or {}).get("validation", {}).get("n_chunks", 1)
    validation_chunk(args.segments, settings, args.chunk, n_chunks, args.errors, args.fits)


def _first_subject(subjects_tsv: str, paths: Paths) -> str:
    """The first subject of the subject sheet, else the first subject with joint angles under ``results/ik``."""
    sheet = Path(subjects_tsv)
    if sheet.is_file():
        from loper_analysis.io.readers import read_subject_sheet

        names = read_subject_sheet(sheet).get("subject", pd.Series(dtype=str))
        if len(names):
            return str(names.iloc[0])
    ik = Path(paths.ik.root)
    found = sorted(p.name for p in ik.glob("*") if p.is_dir())
    if not found:
        raise LoperInputError(f"plan: no subject given, {sheet} not found and no subject under {ik}")
    return found[0]


def _read_config(args: argparse.Namespace) -> tuple[dict | None, str]:
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


def _plan_settings(args: argparse.Namespace, config: dict | None):
    """The planner's settings: those of the rule ``planning`` (the config's,
    :meth:`loper_analysis.planning.pilot_plan.PlanningSettings.from_config`), else the library's defaults; then the
    options given on the command line (targets given replace the config's).
    """
    from loper_analysis.stages.planning.step import PlanningSettings

    settings = PlanningSettings() if config is None else PlanningSettings.from_config(config)
    pulse = {k: v for k, v in (("pulse_force_n", args.force_n), ("pulse_duration_s", args.duration_s)) if v is not None}
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


def _plan_pilot(args: argparse.Namespace, config: dict | None) -> tuple[str | None, str, list[str]]:
    """The pilot subject (``--subject``, else ``planning.pilot_subject``; None: the first of the subject sheet),
    the subject sheet (``--subjects``, else the config's ``subjects``, else ``config/subjects.tsv``) and the
    trials without the device (``--exclude-trials``, else ``trials.no_device``, else the library's)."""
    from loper_analysis.study_design import StudyDesign

    pilot = args.subject or (None if config is None else config["planning"]["pilot_subject"])
    sheet = args.subjects or ("config/subjects.tsv" if config is None else config["subjects"])
    exclude = args.exclude_trials
    if exclude is None:
        exclude = [StudyDesign().no_device if config is None else config["trials"]["no_device"]]
    return pilot, sheet, exclude


def _plan(args: argparse.Namespace) -> None:
    from loper_analysis.planning.precision import PLAN_COLUMNS
    from loper_analysis.stages.planning.files import PilotFiles, PilotTrial
    from loper_analysis.stages.planning.step import plan

    config, line = _read_config(args)
    print(line)
    settings = _plan_settings(args, config)
    pilot, sheet, exclude = _plan_pilot(args, config)
    paths = Paths(results_dir=args.results)
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


def _ik(args: argparse.Namespace) -> None:
    from loper_analysis.io.readers import read_label_maps
    from loper_analysis.motion.ik_settings import IKSettings
    from loper_analysis.stages.ik.step import ik_file
    from loper_analysis.stages.markers.step import MarkerSettings

    config, line = _read_config(args)
    print(line)
    settings = IKSettings() if config is None else IKSettings.from_config(config)
    given = {
        "tasks_file": args.tasks,
        "accuracy": args.accuracy,
        "solver": args.solver,
        "max_marker_rms_m": args.max_marker_rms_m,
        "warn_marker_rms_m": args.warn_marker_rms_m,
        "max_rms_fraction": args.max_rms_fraction,
    }
    settings = dataclasses.replace(settings, **{k: v for k, v in given.items() if v is not None}, subjects_model=False)
    # a C3D holds the lab's labels in the lab's frame (the config's markers.*); a TRC the model's already
    lab = MarkerSettings() if config is None else MarkerSettings.from_config(config)
    label_map = _label_map(args.label_map)
    if label_map is None and config is not None and str(args.markers).lower().endswith(".c3d"):
        label_map = read_label_maps(config["markers"]["label_map"] or None)
    result = ik_file(
        args.model,
        args.markers,
        args.out,
        settings,
        (args.start, args.end),
        _rotation_option(args, args.markers) or lab.rotation_deg,
        label_map,
        _walking_direction(args) or lab.walking_direction,
    )
    left_out = f", {result.n_left_out} left out (too few markers)" if result.n_left_out else ""
    print(
        f"{args.out}: {len(result.time_s)} frames{left_out}, marker error RMS "
        f"{1e3 * np.nanmean(result.marker_rms_m):.2f} mm (max {1e3 * np.nanmax(result.marker_max_m):.2f} mm)"
    )
    if result.warning:
        print(f"warning: {result.warning}", file=sys.stderr)


def _inspect(args: argparse.Namespace) -> None:
    from loper_analysis.motion.filtering import CUTOFF_HZ
    from loper_analysis.stages.inspect import inspect_c3d, inspect_subject
    from loper_analysis.subject_setup import NoTemplateFits

    if args.model is not None or args.marker_set is not None or args.label_map_out is not None:
        if len(args.c3d) != 1:
            raise LoperInputError(
                f"inspect: --model, --marker-set and --label-map-out take one file, got {len(args.c3d)}; without "
                "them several files of one subject choose a marker-set template"
            )
        if args.label_map is not None:
            raise LoperInputError("inspect: --label-map is for a subject's files matched to the templates (no --model)")
        print(inspect_c3d(args.c3d[0], args.model, args.marker_set, args.label_map_out, args.config_out).text, end="")
        return
    config, _ = _read_config(args)
    static_name = "static" if config is None else config["trials"]["static"]
    label_map = args.label_map or (None if config is None else config["markers"]["label_map"] or None)
    cutoff = CUTOFF_HZ if config is None else config["filter"]["cutoff_hz"]
    check = _scaling_dry_run(config)
    try:
        result = inspect_subject(args.c3d, args.config_out, static_name, label_map, cutoff, check)
    except NoTemplateFits as exc:
        print(exc.text, end="")
        raise
    print(result.text, end="")


#: The mass (kg) the dry run of ``inspect`` scales at: the mass changes no scale factor, and the subject's own
#: comes later from the sheet or the static trial's plates.
DRY_RUN_MASS_KG = 70.0


def _scaling_dry_run(config: dict | None):
    """The check ``inspect`` runs on a subject's files before it puts them in place: the ``markers`` step on every
    trial (the written label maps, rotation and cut-off, as the workflow runs it) and the ``model`` step's
    :func:`loper_analysis.stages.model.step.scale` with the written model and ScaleTool setup, into a scratch folder,
    at :data:`DRY_RUN_MASS_KG`. A failure raises LoperInputError saying what fails and what the lab must add."""

    def check(staged) -> str:
        from loper_analysis.stages.markers import step as markers_step
        from loper_analysis.stages.model import step as model_step

        m_settings = markers_step.MarkerSettings.from_config(config) if config else markers_step.MarkerSettings()
        m_settings = dataclasses.replace(m_settings, rotation_deg=staged.rotation_deg, cutoff_hz=staged.cutoff_hz)
        s_settings = model_step.ModelSettings.from_config(config) if config else model_step.ModelSettings()
        s_settings = dataclasses.replace(s_settings, rotation_deg=staged.rotation_deg).for_scaling()
        with tempfile.TemporaryDirectory(prefix="loper-dry-run-") as tmp:
            for c3d in staged.walking_c3d:
                maps = tuple(str(p) for p in staged.label_maps[str(c3d)]) or None
                try:
                    markers_step.markers(
                        c3d, Path(tmp) / "walk.trc", settings=dataclasses.replace(m_settings, label_map=maps)
                    )
                except LoperInputError as exc:
                    raise LoperInputError(
                        f"inspect: nothing written: the walking trial {c3d} fails with the config it would write: "
                        f"{one_line(exc)}"
                    ) from None
            if staged.static_c3d is None:
                return "  dry run: the walking trials' markers read; no static trial, scaling not tried\n"
            trc, out = Path(tmp) / "static.trc", Path(tmp) / "scaled.osim"
            files = model_step.ScaleFiles(staged.files["model"], trc, out, setup_xml=staged.files["scale_setup"])
            maps = tuple(str(p) for p in staged.label_maps[str(staged.static_c3d)]) or None
            try:
                markers_step.markers(
                    staged.static_c3d, trc, settings=dataclasses.replace(m_settings, label_map=maps).for_static()
                )
                model_step.scale(files, DRY_RUN_MASS_KG, s_settings)
            except LoperInputError as exc:
                raise LoperInputError(
                    f"inspect: nothing written: scaling the static trial {staged.static_c3d} with the config it "
                    f"would write fails: {one_line(exc)}; {_what_to_add(str(exc), staged.setup)}"
                ) from None
        return f"  dry run: every trial's markers read and the static trial {staged.static_c3d.name} scaled\n"

    return check


def _what_to_add(message: str, setup) -> str:
    """What the lab must add when scaling its static trial fails: the template markers the message names."""
    import re

    named = [m for m in setup.template.marker_names if re.search(rf"\b{re.escape(m)}\b", message)]
    known = set(setup.template.marker_names)
    pairs = sorted({m for ps, _ in setup.template.measurements.values() for pair in ps for m in pair if m in known})
    if named:
        return (
            f"the lab must add {', '.join(named)} to the static trial (the subject standing still, every marker "
            "seen), or give their labels in a label map (--label-map)"
        )
    return (
        "the lab must add a static trial in which the subject stands still over the scaling window "
        f"(markers.static_duration_s) with the scaling markers seen and labelled as the template's "
        f"({', '.join(pairs)}; a label map row naming the wrong marker shows as a factor out of range)"
    )


def _report(args: argparse.Namespace) -> None:
    from loper_analysis.stages.report.step import write_report

    target = write_report(args.target, snakemake_args=args.snakemake_args)
    print(f"{target}: report written ({target.stat().st_size / 1e6:.1f} MB)")


#: Each subcommand's handler.
_HANDLERS = {
    "markers": _markers,
    "grf": _grf,
    "events": _events,
    "scale": _scale,
    "segments": _segments,
    "ik": _ik,
    "validate": _validate,
    "plan": _plan,
    "inspect": _inspect,
    "report": _report,
}


def command_parser() -> argparse.ArgumentParser:
    """The command's parser, each subcommand with its handler (:func:`loper_analysis.cli_parser.build_parser`)."""
    return build_parser(_HANDLERS, __doc__.splitlines()[0])


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; 0 on success, 2 with one line on standard error when an input cannot serve."""
    args = command_parser().parse_args(argv)
    try:
        refuse_overwriting(args)
        check_option_limits(args)
        refuse_config_code(args)
        args.func(args)
    except Exception as exc:
        if args.traceback:
            raise
        print(f"loper-analysis {args.command}: {one_line(exc)}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
