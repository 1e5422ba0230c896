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

from loper_analysis.cli_checks import check_option_limits, refuse_overwriting
from loper_analysis.errors import LoperInputError, one_line

__all__ = ["main"]


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
    from loper_analysis.steps.markers import MarkerSettings, markers

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
    from loper_analysis.steps.grf import GRFSettings, grf

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
    from loper_analysis.steps.events import EventSettings, events

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
    from loper_analysis.steps.markers import MarkerSettings, markers
    from loper_analysis.steps.model import ModelSettings, ScaleFiles, scale_with_setup

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
    from loper_analysis.steps.model import ModelSettings, anthropometric_segments, segments_from_model_file

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
    from loper_analysis.identification.validation import validation_settings
    from loper_analysis.steps.validation import validation_chunk

    config, line = _read_config(args)
    print(line)
    settings = {} if config is None else validation_settings(config)
    settings.update({k: v for k, v in (("n_starts", args.n_starts), ("seed", args.seed)) if v is not None})
    n_chunks = args.n_chunks if args.n_chunks is not None else (config or {}).get("validation", {}).get("n_chunks", 1)
    validation_chunk(args.segments, settings, args.chunk, n_chunks, args.errors, args.fits)


def _first_subject(subjects_tsv: str, results: Path) -> str:
    """The first subject of the subject sheet, else the first subject with joint angles under ``results/ik``."""
    sheet = Path(subjects_tsv)
    if sheet.is_file():
        from loper_analysis.io.readers import read_subject_sheet

        names = read_subject_sheet(sheet).get("subject", pd.Series(dtype=str))
        if len(names):
            return str(names.iloc[0])
    found = sorted(p.name for p in (results / "ik").glob("*") if p.is_dir())
    if not found:
        raise LoperInputError(f"plan: no subject given, {sheet} not found and no subject under {results / 'ik'}")
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
    :meth:`loper_analysis.steps.planning.PlanningSettings.from_config`), else the library's defaults; then the
    options given on the command line (targets given replace the config's).
    """
    from loper_analysis.steps.planning import PlanningSettings

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
    from loper_analysis.steps.planning import PilotFiles, PilotTrial, plan

    config, line = _read_config(args)
    print(line)
    settings = _plan_settings(args, config)
    pilot, sheet, exclude = _plan_pilot(args, config)
    results = Path(args.results)
    subject = pilot or _first_subject(sheet, results)
    ik_dir = results / "ik" / subject
    names = args.trials or sorted(p.name.removesuffix(".angles.tsv") for p in ik_dir.glob("*.angles.tsv"))
    names = [n for n in names if n not in exclude]
    if not names:
        raise LoperInputError(
            f"plan: no joint-angle table of a trial with the device in {ik_dir} (excluded: {', '.join(exclude)})"
        )
    trials = {
        n: PilotTrial(angles=ik_dir / f"{n}.angles.tsv", strides=results / "strides" / subject / f"{n}.strides.tsv")
        for n in names
    }
    for path in [*(t.angles for t in trials.values()), *(t.strides for t in trials.values())]:
        if not path.is_file():
            raise LoperInputError(f"plan: {path} not found")
    segments = Path(args.segments) if args.segments else results / "model" / subject / "segments.tsv"
    impedance_tsvs = (
        [Path(f) for f in args.impedance]
        if args.impedance
        else sorted((results / "impedance" / subject).glob("[0-9][0-9][0-9].tsv"))
    )
    values = args.impedance_values
    if settings.onsets_ms is None:
        if values is not None:
            raise LoperInputError("plan: with --impedance-values give --onset-ms")
        onsets = [int(p.stem) for p in impedance_tsvs if p.stem.isdigit()]
        if not onsets:
            raise LoperInputError(
                f"plan: no impedance rows of {subject} in {results / 'impedance' / subject}; "
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
    from loper_analysis.steps.ik import IKSettings, ik_file
    from loper_analysis.steps.markers import MarkerSettings

    config, line = _read_config(args)
    print(line)
    settings = IKSettings() if config is None else IKSettings.from_config(config)
    given = {
        "tasks_file": args.tasks,
        "accuracy": args.accuracy,
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
    from loper_analysis.steps.inspect import inspect_c3d, inspect_subject
    from loper_analysis.subject_setup import NoTemplateFits

    if args.model is not None or args.marker_set is not None or args.label_map_out is not None:
        if len(args.c3d) != 1:
            raise LoperInputError(
                f"inspect: --model, --marker-set and --label-map-out take one file, got {len(args.c3d)}; without "
                "them several files of one subject choose a marker-set template"
            )
        print(inspect_c3d(args.c3d[0], args.model, args.marker_set, args.label_map_out, args.config_out).text, end="")
        return
    config, _ = _read_config(args)
    static_name = "static" if config is None else config["trials"]["static"]
    try:
        result = inspect_subject(args.c3d, args.config_out, static_name)
    except NoTemplateFits as exc:
        print(exc.text, end="")
        raise
    print(result.text, end="")


def _report(args: argparse.Namespace) -> None:
    from loper_analysis.steps.report import write_report

    target = write_report(args.target, snakemake_args=args.snakemake_args)
    print(f"{target}: report written ({target.stat().st_size / 1e6:.1f} MB)")


def _rotate_option(p: argparse.ArgumentParser, heading: bool = False) -> None:
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


def _label_map_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--label-map",
        metavar="MAP",
        help="TSV (columns label, marker) or YAML mapping: lab label -> "
        "model marker; subject prefixes (Name:) are stripped first (default for a .c3d: markers.label_map)",
    )


def _configfile_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--configfile",
        nargs="+",
        metavar="FILE",
        help="config file(s) layered over config/config.yaml "
        "of the working directory (when present), each over the ones before, as snakemake --configfile "
        "does; default: config/config.yaml alone",
    )


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="loper-analysis", description=__doc__.splitlines()[0])
    parser.add_argument("--traceback", action="store_true", help="show the Python traceback of a failure")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("markers", help="C3D markers -> TRC (mm) in the model frame")
    p.add_argument("c3d", help="marker file (.c3d)")
    p.add_argument("--out", required=True, help="output .trc")
    p.add_argument("--gaps", help="output TSV: per marker, frames filled and left missing")
    _label_map_option(p)
    _rotate_option(p, heading=True)
    p.add_argument(
        "--cutoff-hz", type=float, help="zero-phase Butterworth low-pass (Hz); 0: no filter (default: filter.cutoff_hz)"
    )
    p.add_argument("--order", type=int, help="designed filter order, run forward and backward (default: filter.order)")
    p.add_argument(
        "--max-gap-frames",
        type=int,
        help="fill gaps up to this many frames; 0: no filling (default: markers.max_gap_frames)",
    )
    _configfile_option(p)
    p.set_defaults(func=_markers)

    p = sub.add_parser("grf", help="C3D force platforms -> OpenSim external-loads .mot")
    p.add_argument("c3d", help="C3D file with a FORCE_PLATFORM group")
    p.add_argument("--out", required=True, help="output .mot (columns {n}_ground_force_v*, _p*, {n}_ground_torque_*)")
    _rotate_option(p)
    p.add_argument(
        "--threshold-n",
        type=float,
        help="loaded above this vertical force over rest (N; default: grf.loaded_threshold_n)",
    )
    _configfile_option(p)
    p.set_defaults(func=_grf)

    p = sub.add_parser("events", help="heel strikes and toe-offs from the force platforms -> TSV")
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
    _label_map_option(p)
    _rotate_option(p)
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
    _configfile_option(p)
    p.set_defaults(func=_events)

    p = sub.add_parser("scale", help="scale a generic model with a lab's ScaleTool setup and a static trial")
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
        help="first time of the static trial to use (s; default: the setup's time range, else the first "
        "markers.static_duration_s)",
    )
    p.add_argument("--end", type=float, help="last time of the static trial to use (s)")
    p.add_argument(
        "--max-motion-rms-m",
        type=float,
        help="refuse a static trial with a marker moving "
        "more than this (m, RMS about its mean over the window; 0: not checked; default: "
        "markers.static_max_motion_rms_m)",
    )
    _label_map_option(p)
    _rotate_option(p)
    p.add_argument("--cutoff-hz", type=float, default=0.0, help="low-pass of a .c3d static trial (Hz); 0: none")
    p.add_argument(
        "--max-gap-frames",
        type=int,
        default=0,
        help="fill gaps of a .c3d static trial up to this "
        "(default 0: each marker is averaged over the frames where it is present)",
    )
    _configfile_option(p)
    p.set_defaults(func=_scale)

    p = sub.add_parser("segments", help="segment table (TSV) from a scaled model, or from height and mass")
    p.add_argument("--model", help="scaled OpenSim model (.osim): gait2392, Rajagopal2016 or the generated model")
    p.add_argument(
        "--side", choices=("left", "right"), help="the swing leg (with --model; default: trials.perturbed_side)"
    )
    p.add_argument("--height-m", type=float, help="without --model: Winter's table from height ...")
    p.add_argument("--mass-kg", type=float, help="... and body mass")
    p.add_argument(
        "--attachment-fraction",
        type=float,
        help="brace position along the thigh (fraction of its length; a model's brace markers win; default: "
        "opensim.brace_attachment_fraction)",
    )
    p.add_argument("--out", required=True, help="output TSV")
    _configfile_option(p)
    p.set_defaults(func=_segments)

    p = sub.add_parser("ik", help="OpenSim inverse kinematics of a .c3d or .trc marker file to a .mot (degrees)")
    p.add_argument("--model", required=True, help="OpenSim model (.osim)")
    p.add_argument("--markers", required=True, help="marker file: .c3d (units from POINT:UNITS) or .trc (Units header)")
    p.add_argument("--out", required=True, help="output .mot (angles in degrees, OpenSim's convention)")
    p.add_argument(
        "--tasks",
        help="OpenSim IK task-set XML or TSV (name, kind, weight[, value]); default: opensim.ik_tasks, else "
        "every model marker found in the file, weight 1",
    )
    p.add_argument("--start", type=float, help="first time (s) to solve")
    p.add_argument("--end", type=float, help="last time (s) to solve")
    _label_map_option(p)
    _rotate_option(p, heading=True)
    p.add_argument(
        "--accuracy", type=float, help="IK solver accuracy (default: opensim.accuracy; OpenSim's own default 1e-5)"
    )
    p.add_argument(
        "--max-marker-rms-m",
        type=float,
        help="a frame whose marker RMS error exceeds this (m) counts as failed (a unit, label or model mistake; "
        "default: opensim.max_marker_rms_m)",
    )
    p.add_argument(
        "--warn-marker-rms-m",
        type=float,
        help="a frame whose marker RMS error exceeds this (m) counts as poorly fitted (a warning; default: "
        "opensim.warn_marker_rms_m)",
    )
    p.add_argument(
        "--max-rms-fraction",
        type=float,
        help="fail (warn) when more frames than this share fail (fit poorly; default: opensim.max_rms_fraction)",
    )
    _configfile_option(p)
    p.set_defaults(func=_ik)

    p = sub.add_parser(
        "validate",
        help="one chunk of the validation study (the study's design)",
        description="Simulate and identify one chunk of the validation study with the settings of the workflow's "
        "validation rules: config/config.yaml of the working directory with each --configfile over it "
        "(validation.*, identification.*, seed); options given here win; without any config file the "
        "library's defaults (said in the first line printed).",
    )
    _configfile_option(p)
    p.add_argument("--segments", required=True, help="segment table TSV")
    p.add_argument("--chunk", type=int, default=0)
    p.add_argument("--n-chunks", type=int, help="chunks of the study (default: validation.n_chunks of the config)")
    p.add_argument("--n-starts", type=int, help="multistart starts (default: identification.n_starts)")
    p.add_argument("--seed", type=int, help="seed (default: the config's seed)")
    p.add_argument("--errors", required=True, help="output TSV, one row per combination x condition x parameter")
    p.add_argument("--fits", required=True, help="output TSV, one row per combination x condition")
    p.set_defaults(func=_validate)

    p = sub.add_parser(
        "plan",
        help="predicted 95 %% CI half-width of K and D for a planned experiment (pilot subject)",
        description="Predict the 95 % CI half-width of K and D of a planned experiment from a pilot "
        "subject's processed trials, with the settings of the workflow's rule 'planning'. Settings, "
        "highest priority first: (1) options given here; (2) the config: config/config.yaml of the "
        "working directory with each --configfile over it, as Snakemake layers them (onsets: "
        "trials.perturbation_onsets_ms; strides, targets, pulse and pilot: planning.*; fit window, "
        "initial state, bounds, null pairs and the counterfactual planned for: identification.*; outliers: "
        "strides.iqr_whisker, "
        "strides.max_outlier_fraction; device: device.parameters; excluded trial: trials.no_device; "
        "subject sheet: subjects); (3) without any config file, the library's defaults (said in the "
        "first line printed, which names the config file(s) used).",
    )
    _configfile_option(p)
    p.add_argument("--results", default="results", help="results folder of the pilot's processed trials")
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
        "--exclude-trials", nargs="*", help="trials without the device (default: trials.no_device, else walk-nodevice)"
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
        help="onsets after toe-off (ms; default: trials.perturbation_onsets_ms, else those of the impedance rows)",
    )
    p.add_argument(
        "--strides", type=int, nargs="+", help="perturbed strides averaged (default: planning.strides, else 10 20 40)"
    )
    p.add_argument("--force-n", type=float, help="pulse: desired force (N; default: planning.pulse_force_n, else 40)")
    p.add_argument("--duration-s", type=float, help="pulse duration (s; default: planning.pulse_duration_s, else 0.1)")
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
    p.set_defaults(func=_plan)

    p = sub.add_parser(
        "inspect",
        help="what a lab's C3D files hold; a subject's config from a marker-set template, or labels matched to a model",
        description="Without --model: a subject's files (static and walking trials, their kinds from their names) "
        "are matched to the marker-set templates, and --config-out writes the subject's config with the model, "
        "marker set, ScaleTool setup, IK tasks and label map beside it. With --model: one file's labels matched "
        "to that model's markers, a starter label map and a config snippet.",
    )
    p.add_argument("c3d", nargs="+", help="the lab's C3D file(s) of one subject (static.c3d, walk-nodevice.c3d, ...)")
    p.add_argument("--model", metavar="M.osim", help="OpenSim model whose markers the file's labels are matched to")
    p.add_argument("--marker-set", metavar="SET.xml", help="OpenSim MarkerSet whose markers are added to the model's")
    p.add_argument(
        "--label-map-out", metavar="MAP.tsv", help="write the starter label map (label, marker; needs --model)"
    )
    p.add_argument(
        "--config-out",
        metavar="CONFIG.yaml",
        help="without --model: the subject's config (files it names beside it); with --model: a config snippet "
        "(rotation, label map, heel markers, model) to merge over the configuration",
    )
    _configfile_option(p)
    p.set_defaults(func=_inspect)

    p = sub.add_parser(
        "report",
        help="the Snakemake report, written beside its target and moved over it when whole",
        description="Run `snakemake --report` (this Python's Snakemake) into a temporary file beside "
        "TARGET, check that it is complete (an HTML report ends with </html>) and move it over "
        "TARGET; on any failure the previous report stays as it was.",
    )
    p.add_argument("target", help="the report: .html (one self-contained file) or .zip, e.g. results/report.html")
    p.add_argument(
        "snakemake_args",
        nargs=argparse.REMAINDER,
        metavar="SNAKEMAKE_ARGS",
        help="passed on to snakemake after --report, e.g. --configfile my.yaml",
    )
    p.set_defaults(func=_report)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one subcommand; 0 on success, 2 with one line on standard error when an input cannot serve."""
    args = _parser().parse_args(argv)
    try:
        refuse_overwriting(args)
        check_option_limits(args)
        args.func(args)
    except Exception as exc:
        if args.traceback:
            raise
        print(f"loper-analysis {args.command}: {one_line(exc)}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
