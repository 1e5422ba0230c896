"""The options of the ``loper-analysis`` command: one function per subcommand adds its parser.

:func:`build_parser` builds the whole parser with the subcommands' handlers (:mod:`loper_analysis.cli`).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable, Mapping

from loper_analysis.layout import RESULTS_DIR

__all__ = ["SUBCOMMANDS", "build_parser"]


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


def _add_markers(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``markers`` subcommand."""
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
    p.set_defaults(func=handlers["markers"])


def _add_grf(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``grf`` subcommand."""
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
    p.set_defaults(func=handlers["grf"])


def _add_events(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``events`` subcommand."""
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
    p.set_defaults(func=handlers["events"])


def _add_scale(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``scale`` subcommand."""
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
        help="first time of the static trial to use (s; default: the setup's time range, else the stillest "
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
    p.set_defaults(func=handlers["scale"])


def _add_segments(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``segments`` subcommand."""
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
    p.set_defaults(func=handlers["segments"])


def _add_ik(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``ik`` subcommand."""
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
        "--solver",
        choices=("tree", "opensim"),
        help="IK solver (default: opensim.ik_solver): the model's kinematic tree or OpenSim's",
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
    p.set_defaults(func=handlers["ik"])


def _add_validate(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``validate`` subcommand."""
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
    p.set_defaults(func=handlers["validate"])


def _add_plan(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``plan`` subcommand."""
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
    p.set_defaults(func=handlers["plan"])


def _add_inspect(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``inspect`` subcommand."""
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
        "--label-map",
        metavar="MAP.tsv",
        help="without --model: the lab's label map (label, marker; TSV or YAML), applied before the labels are "
        "matched to the templates, e.g. a completed label_map_starter.tsv (rows left empty are skipped); "
        "default: markers.label_map of the config",
    )
    p.add_argument(
        "--config-out",
        metavar="CONFIG.yaml",
        help="without --model: the subject's config (files it names beside it); with --model: a config snippet "
        "(rotation, label map, heel markers, model) to merge over the configuration",
    )
    _configfile_option(p)
    p.set_defaults(func=handlers["inspect"])


def _add_report(sub, handlers: Mapping[str, Callable]) -> None:
    """The ``report`` subcommand."""
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
    p.set_defaults(func=handlers["report"])


#: Each subcommand and the function that adds its parser, in the order ``--help`` lists them.
_ADDERS = {
    "markers": _add_markers,
    "grf": _add_grf,
    "events": _add_events,
    "scale": _add_scale,
    "segments": _add_segments,
    "ik": _add_ik,
    "validate": _add_validate,
    "plan": _add_plan,
    "inspect": _add_inspect,
    "report": _add_report,
}
#: The subcommands.
SUBCOMMANDS: tuple[str, ...] = tuple(_ADDERS)


def build_parser(handlers: Mapping[str, Callable], description: str = "") -> argparse.ArgumentParser:
    """The command's parser; ``handlers`` maps each of :data:`SUBCOMMANDS` to the function that runs it
    (``args.func``)."""
    parser = argparse.ArgumentParser(prog="loper-analysis", description=description)
    parser.add_argument("--traceback", action="store_true", help="show the Python traceback of a failure")
    sub = parser.add_subparsers(dest="command", required=True)
    for add in _ADDERS.values():
        add(sub, handlers)
    return parser
