"""The ``loper-analysis`` command: each stage of the pipeline on one file, with the functions the rules call.

Subcommands
-----------
markers      C3D markers -> label map, gap fill, lab -> model frame, low-pass -> TRC (mm)
scale        scale a generic OpenSim model with a lab's ScaleTool setup and a static trial
segments     swing-leg segment table from a scaled model, or from height and mass (Winter's table)
ik           OpenSim inverse kinematics of a marker file (.c3d or .trc) to a .mot
grf          C3D force platforms -> OpenSim external-loads .mot (model frame)
events       heel strikes and toe-offs from the force platforms (or named GRF channels) -> events TSV
plan         predict the 95 % CI half-width of K and D of a planned experiment from a pilot subject
validate     run (part of) the validation study and write its tables
report       the Snakemake report (``snakemake --report``) written beside its target and moved over it when whole
inspect      what a lab's C3D files hold; a subject's config from a marker-set template (or labels matched to a model)

Each stage's subcommands live in its slice (``loper_analysis.stages.<name>.command``), listed in the order of the
stages; ``inspect``, which belongs to no stage, lives here.

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

from loper_analysis.cli_checks import check_option_limits, refuse_config_code, refuse_overwriting
from loper_analysis.cli_options import read_config
from loper_analysis.cli_parser import STAGE_COMMANDS, build_parser
from loper_analysis.errors import LoperInputError, one_line
from loper_analysis.stages.planning.command import plan_pilot, plan_settings
from loper_analysis.stages.settings import stage_settings

__all__ = ["command_parser", "main"]

# the planner's helpers and the config's reader under the names this module gave them before the stages' commands
_plan_pilot, _plan_settings, _read_config = plan_pilot, plan_settings, read_config


def _inspect(args: argparse.Namespace) -> None:
    from loper_analysis.filtering import CUTOFF_HZ
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
    config, _ = read_config(args)
    marker_settings = None if config is None else stage_settings(config, "markers")
    static_name = "static" if config is None else stage_settings(config, "study").design.static
    label_map = args.label_map or (None if marker_settings is None else marker_settings.label_map)
    cutoff = CUTOFF_HZ if marker_settings is None else marker_settings.cutoff_hz
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
        from loper_analysis.stages.settings import stage_settings

        m_settings = stage_settings(config, "markers") if config else markers_step.MarkerSettings()
        m_settings = dataclasses.replace(m_settings, rotation_deg=staged.rotation_deg, cutoff_hz=staged.cutoff_hz)
        s_settings = stage_settings(config, "model") if config else model_step.ModelSettings()
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
        f"(model.static_duration_s) with the scaling markers seen and labelled as the template's "
        f"({', '.join(pairs)}; a label map row naming the wrong marker shows as a factor out of range)"
    )


#: Each subcommand's handler.
_HANDLERS = {**{c.name: c.run for c in STAGE_COMMANDS}, "inspect": _inspect}


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
