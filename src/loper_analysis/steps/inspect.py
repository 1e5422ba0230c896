"""File step of ``loper-analysis inspect``: what a lab's C3D file holds, a starter label map and config snippet.

Reads the C3D file (:func:`loper_analysis.io.c3d.read_c3d`, its force
platforms with :func:`loper_analysis.io.force_platforms.read_force_platforms`
and ``POINT:UNITS``), optionally an OpenSim model and a marker set whose
markers are added to the model's, and hands the records to
:mod:`loper_analysis.inspection` (the lab's axes from
:mod:`loper_analysis.motion.lab_frame`, labels matched to the model's markers by
:mod:`loper_analysis.motion.label_matching`). The label map and the config
snippet are written through the atomic writer (:mod:`loper_analysis.io.atomic`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from loper_analysis.errors import LoperInputError, one_line
from loper_analysis.inspection import RecordingSummary, config_snippet, recording_summary, yaml_flow
from loper_analysis.inspection_text import format_label_match, format_summary
from loper_analysis.io.atomic import PathLike, write_bytes, write_text, write_tsv
from loper_analysis.io.c3d_parameters import param_strings
from loper_analysis.io.timing import library_import, timed_io
from loper_analysis.motion.lab_frame import axis_name
from loper_analysis.motion.label_matching import LabelMatch, heel_markers, match_labels, starter_label_map
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.subject_setup import NoTemplateFits, SubjectSetup, format_fits

if TYPE_CHECKING:
    from loper_analysis.io.c3d import C3DRecording

__all__ = ["Inspection", "SubjectInspection", "inspect_c3d", "inspect_subject", "model_marker_names_of"]


@dataclass(frozen=True)
class Inspection:
    """What :func:`inspect_c3d` found and wrote.

    Attributes
    ----------
    summary : RecordingSummary
        The recording (:func:`loper_analysis.inspection.recording_summary`).
    match : LabelMatch or None
        Labels matched to the model's markers (None without a model).
    model_markers : tuple of str
        The model's markers (with the marker set's), empty without a model.
    text : str
        The report to print.
    label_map_out, config_out : Path or None
        The files written.
    """

    summary: RecordingSummary
    match: LabelMatch | None
    model_markers: tuple[str, ...]
    text: str
    label_map_out: Path | None = None
    config_out: Path | None = None


@timed_io
def _point_unit(path: Path) -> str:
    """``POINT:UNITS`` of a C3D file as declared ("" when absent); the file has been read by read_c3d already."""
    with library_import():
        import ezc3d

    try:
        params = ezc3d.c3d(str(path))["parameters"]
    except Exception as exc:  # ezc3d raises RuntimeError, ValueError, ... for damaged files
        raise LoperInputError(f"{path}: not a readable C3D file: {type(exc).__name__}: {exc}") from exc
    units = param_strings(params, "POINT", "UNITS")
    return units[0] if units else ""


def _recording(path: Path) -> tuple:
    """A C3D file read with its force platforms, and its summary
    (:func:`loper_analysis.inspection.recording_summary`); plates that cannot be read are reported in it."""
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.force_platforms import read_force_platforms

    rec = read_c3d(path)
    plates, problem = [], ""
    if rec.n_force_platforms:
        try:
            plates = read_force_platforms(path)
        except LoperInputError as exc:
            problem = one_line(exc)
    return rec, recording_summary(rec, plates, point_unit=_point_unit(path), plate_problem=problem)


def model_marker_names_of(model_osim: PathLike, marker_set_xml: PathLike | None = None) -> list[str]:
    """Names of a model's markers, followed by those of a marker set the model lacks (as ScaleTool adds them).

    Raises
    ------
    LoperInputError
        The model or the marker set is missing or unreadable (naming the file).
    """
    from loper_analysis.io.osim import read_marker_set, read_model

    model = read_model(model_osim)
    ms = model.getMarkerSet()
    names = [ms.get(i).getName() for i in range(ms.getSize())]
    if marker_set_xml is not None:
        extra = read_marker_set(marker_set_xml)
        names += [extra.get(i).getName() for i in range(extra.getSize())]
    return list(dict.fromkeys(names))


def _snippet(
    summary: RecordingSummary,
    c3d_name: str,
    snippet_path: str,
    label_map,
    feet,
    model: str | None,
    with_marker_set: bool,
) -> str:
    """The config snippet's text, a comment on every key."""
    walking = summary.walking
    rotation = f"from {c3d_name}: up {axis_name(summary.vertical.axis, summary.vertical.sign)} -> model +Y"
    if walking.axis is None:
        rotation += "; treadmill/standing: check that the subject faces model +X"
    elif summary.rotation_forward_deg != summary.rotation_deg:
        rotation += (
            f"; this trial walks {axis_name(walking.axis, walking.sign)}, "
            f"[{', '.join(f'{a:g}' for a in summary.rotation_forward_deg)}] turns it to model +X"
        )
    notes = {
        "rotation": rotation,
        "label_map": "lab label -> model marker; check every row, add the unmatched labels you need",
        "foot_markers": "heel markers (model names) that assign plate contacts to feet",
        "generic_model": "scaled per subject with opensim.scale_setup, your ScaleTool setup"
        + (" (it names the marker set)" if with_marker_set else ""),
    }
    header = [
        f"Starter settings from loper-analysis inspect {c3d_name}. Check them, then run",
        f"snakemake --configfile {snippet_path} (it goes over config/config.yaml).",
        "Paths are as given to inspect: relative ones count from where snakemake runs.",
    ]
    return config_snippet(summary.rotation_deg, label_map, feet, model, notes, header)


def inspect_c3d(
    c3d_path: PathLike,
    model_osim: PathLike | None = None,
    marker_set_xml: PathLike | None = None,
    label_map_out: PathLike | None = None,
    config_out: PathLike | None = None,
) -> Inspection:
    """Inspect a C3D file; optionally match its labels to a model and write a label map and a config snippet.

    Parameters
    ----------
    c3d_path : path-like
        The lab's ``.c3d`` file.
    model_osim : path-like, optional
        OpenSim model whose markers the labels are matched to.
    marker_set_xml : path-like, optional
        OpenSim MarkerSet XML whose markers are added to the model's (needs ``model_osim``).
    label_map_out : path-like, optional
        TSV (columns ``label``, ``marker``) of the matched labels whose name differs from
        their marker (needs ``model_osim``); unmatched labels are only printed.
    config_out : path-like, optional
        YAML snippet: ``markers.lab_to_model_rotation_deg``, ``markers.label_map`` (the map
        written, or inline), ``events.foot_markers`` (when both heels are found) and
        ``opensim.generic_model`` (with a model).

    Returns
    -------
    Inspection
        The summary, the match and the text to print (naming the files written).

    Raises
    ------
    LoperInputError
        A missing or unreadable C3D file, model or marker set; ``marker_set_xml`` or
        ``label_map_out`` without ``model_osim``. Force platforms that cannot be read are
        reported in the text instead.
    """

    if model_osim is None and marker_set_xml is not None:
        raise LoperInputError(f"{marker_set_xml}: a marker set is added to a model: give --model as well")
    if model_osim is None and label_map_out is not None:
        raise LoperInputError(f"{label_map_out}: a label map needs a model to match the labels to: give --model")
    path = Path(c3d_path)
    rec, summary = _recording(path)
    text = format_summary(summary)

    match, model_markers = None, ()
    if model_osim is not None:
        model_markers = tuple(model_marker_names_of(model_osim, marker_set_xml))
        match = match_labels(rec.marker_labels, model_markers)
        name = Path(model_osim).name + (f" + {Path(marker_set_xml).name}" if marker_set_xml else "")
        text += "\n" + format_label_match(match, name, len(model_markers))

    written = []
    table = starter_label_map(match) if match is not None else None
    if label_map_out is not None:
        write_tsv(table, label_map_out)
        written.append(
            f"{label_map_out}: label map, {len(table)} row(s) (labels named like their model marker "
            "need none; unmatched labels are listed above, not in the map)"
        )
    if config_out is not None:
        label_map = None
        if match is not None:
            label_map = str(label_map_out) if label_map_out is not None else dict(zip(table["label"], table["marker"]))
        names = (
            [m for _, m, _ in match.pairs]
            if match is not None
            else [strip_subject_prefix(lab) for lab in rec.marker_labels]
        )
        feet = heel_markers(names)
        model = None if model_osim is None else str(model_osim)
        write_text(
            config_out,
            _snippet(summary, path.name, str(config_out), label_map, feet, model, marker_set_xml is not None),
            "config snippet",
        )
        written.append(
            f"{config_out}: config snippet (markers.lab_to_model_rotation_deg"
            + (", markers.label_map" if label_map is not None else "")
            + (", events.foot_markers" if feet else "")
            + (", opensim.generic_model" if model is not None else "")
            + ")"
        )
    if written:
        text += "\n" + "\n".join(written) + "\n"
    return Inspection(
        summary,
        match,
        model_markers,
        text,
        None if label_map_out is None else Path(label_map_out),
        None if config_out is None else Path(config_out),
    )


# ---------------------------------------------------------------- a subject's files -> its config


@dataclass(frozen=True)
class SubjectInspection:
    """What :func:`inspect_subject` found and wrote.

    Attributes
    ----------
    summaries : list of RecordingSummary
        One per file, in the order given.
    setup : SubjectSetup or None
        The template and what follows (None when no config was asked for and no template fits).
    text : str
        The report to print.
    written : tuple of Path
        The files written (the config last).
    """

    summaries: list[RecordingSummary]
    setup: SubjectSetup | None
    text: str
    written: tuple[Path, ...] = ()


def _trial_kind(path: Path, static_name: str) -> str:
    return "static" if path.stem == static_name else "walking"


def _subject_config_text(
    paths: Sequence[Path],
    kinds: Sequence[str],
    setup: SubjectSetup,
    summary: RecordingSummary,
    files: Mapping[str, str],
    coordinate_map: Mapping[str, Mapping],
    mass_height: str,
) -> str:
    """The subject's config: every key with a comment (YAML)."""
    t = setup.template
    rotation = [float(a) for a in summary.rotation_deg]
    up = axis_name(summary.vertical.axis, summary.vertical.sign)
    lines = [
        f"# Settings of the subject recorded in {', '.join(str(p) for p in paths)}, written by loper-analysis inspect.",
        f"# Marker-set template: {t.name} ({t.title}) on {t.model}.",
        "# Add the subject to a sheet (subject, source: recorded, ...) named by `subjects:` below, then run",
        f"#   snakemake -j2 --configfile {files['config']}",
        f"# {mass_height}",
        "# subjects: lab/subjects.tsv          # the subject sheet (add this key)",
        "markers:",
        f"  lab_to_model_rotation_deg: {yaml_flow(rotation)}   # up {up} -> model +Y (each walking trial is turned "
        "to walk along model +X)",
    ]
    if "label_map" in files:
        lines.append(f"  label_map: {yaml_flow(files['label_map'])}   # lab label -> template marker")
    else:
        lines.append("  label_map: {}   # the labels are the template's marker names")
    lines += [
        "opensim:",
        f"  generic_model: {yaml_flow(files['model'])}   # {t.model} as OpenSim distributes it",
        f"  scale_setup: {yaml_flow(files['scale_setup'])}   # ScaleTool setup; names marker_set.xml beside it",
        f"  ik_tasks: {yaml_flow(files['ik_tasks'])}   # markers of the walking trials and their weights"
        + (f"; not tracked (static trial only): {', '.join(setup.static_only)}" if setup.static_only else ""),
        "  coordinate_map:   # our angle -> model coordinate; each sign read from the model's kinematics",
    ]
    lines += [f"    {k}: {yaml_flow(dict(v))}" for k, v in coordinate_map.items()]
    feet = t.foot_markers
    lines += ["events:", f"  foot_markers: {yaml_flow(dict(feet))}   # heel markers: assign plate contacts to feet"]
    kinds_text = ", ".join(f"{p.stem} ({k})" for p, k in zip(paths, kinds))
    lines.append(f"# trials: {kinds_text}")
    return "\n".join(lines) + "\n"


def _mass_height_line(static_rec) -> str:
    """Where the subject's mass and height will come from when the sheet leaves them empty."""
    parts = []
    if static_rec is not None and static_rec.n_force_platforms:
        parts.append("mass: the static trial's force plates")
    elif static_rec is not None and "Bodymass" in static_rec.processing:
        parts.append(f"mass: {static_rec.processing['Bodymass']:.2f} kg (the file's PROCESSING:Bodymass)")
    if static_rec is not None and "Height" in static_rec.processing:
        parts.append(f"height: {static_rec.processing['Height'] / 1000:.3f} m (PROCESSING:Height)")
    return "Without mass or height in the sheet: " + ("; ".join(parts) or "give them in the sheet") + "."


def inspect_subject(
    c3d_paths: Sequence[PathLike],
    config_out: PathLike | None = None,
    static_name: str = "static",
) -> SubjectInspection:
    """Inspect a subject's C3D files, choose the marker-set template that fits their labels, and (``config_out``)
    write the subject's config with the files it names beside it.

    Each file's kind comes from its name: ``static_name`` (``trials.static``) is the static trial, every other
    file a walking trial. The template (:func:`loper_analysis.subject_setup.subject_setup`) gives the label
    map, the marker set of the static trial's markers, a ScaleTool setup naming it, the walking trials' IK
    tasks (a marker of the static trial only is not tracked) and the heel markers; the coordinate map's signs
    are read from the template's model
    (:func:`loper_analysis.motion.marker_templates.template_coordinate_map`).

    Written beside ``config_out`` (paths in the config as given, so relative ones count from where snakemake
    runs): the model (a copy), ``marker_set.xml``, ``scale_setup.xml``, ``ik_tasks.tsv``, ``label_map.tsv``
    (when a label differs from its marker), then the config. Everything is built before anything is written.

    Raises
    ------
    LoperInputError
        A missing or unreadable file; an output path equal to an input.
    loper_analysis.subject_setup.NoTemplateFits
        The labels fit no template: the message lists what was and was not mapped; with ``config_out`` a
        starter map (``label_map_starter.tsv``: every label, the template's marker where one was found) is
        written beside it and nothing else.
    """
    from loper_analysis.io.marker_templates import read_templates
    from loper_analysis.subject_setup import subject_setup

    paths = [Path(p) for p in c3d_paths]
    if config_out is not None and any(Path(config_out).resolve() == p.resolve() for p in paths):
        raise LoperInputError(f"{config_out}: the config would overwrite an input file")
    kinds = [_trial_kind(p, static_name) for p in paths]
    recs, summaries, text = _recordings_text(paths)
    static = next((r for r, k in zip(recs, kinds) if k == "static"), None)
    walking = [r.marker_labels for r, k in zip(recs, kinds) if k == "walking"]
    source = ", ".join(str(p) for p in paths)
    templates = read_templates()
    try:
        setup = subject_setup(None if static is None else static.marker_labels, walking, templates, source)
    except NoTemplateFits as exc:
        exc.text = (
            text + f"\nMarker-set templates (required marker groups found, markers found):\n{format_fits(exc.fits)}\n"
        )
        if config_out is not None:
            raise _starter_map_error(exc, recs, config_out) from None
        raise
    text += _template_text(setup)
    if static is None:
        text += "  no static trial among the files: its markers were taken from the first walking trial\n"
    mass_height = _mass_height_line(static)
    text += f"  {mass_height}\n"
    if config_out is None:
        return SubjectInspection(summaries, setup, text)

    written = _written_subject_files(paths, kinds, setup, summaries[0], config_out, mass_height)
    text += "\n" + "\n".join(f"wrote {w}" for w in written) + "\n"
    device = any(k == "walking" and p.stem != "walk-nodevice" and "device" in p.stem for p, k in zip(paths, kinds))
    text += (
        "next: add `subjects:` (a sheet with the row `SUBJECT recorded`) to the config"
        + ("" if device else ", and `device.subject: null` (no device trials)")
        + f", then: snakemake -j2 --configfile {config_out}\n"
    )
    return SubjectInspection(summaries, setup, text, written)


def _recordings_text(paths: Sequence[Path]) -> tuple[list[C3DRecording], list[RecordingSummary], str]:
    """The C3D files read (:func:`_recording`), their summaries and the summaries' text, in the order given."""
    recs, summaries, text = [], [], ""
    for path in paths:
        rec, summary = _recording(path)
        recs.append(rec)
        summaries.append(summary)
        text += format_summary(summary) + "\n"
        if rec.output_labels:
            text += (
                f"  {len(rec.output_labels)} point(s) that are not markers left out (the lab's model outputs, segment "
                f"and unlabelled points); {len(rec.marker_labels)} markers\n"
            )
    return recs, summaries, text


def _starter_map_error(exc: NoTemplateFits, recs: Sequence[C3DRecording], config_out: PathLike) -> NoTemplateFits:
    """Write the starter label map (``label_map_starter.tsv`` beside ``config_out``: every label of ``recs``,
    the best template's marker where one was found) and return the error naming it (``exc``'s fits and text)."""
    best = exc.fits[0].match
    marker_of = {strip_subject_prefix(lab): m for lab, m, _ in best.pairs}
    labels = list(dict.fromkeys(strip_subject_prefix(lab) for r in recs for lab in r.marker_labels))
    starter = Path(config_out).parent / "label_map_starter.tsv"
    write_tsv(pd.DataFrame({"label": labels, "marker": [marker_of.get(lab, "") for lab in labels]}), starter)
    error = NoTemplateFits(
        f"{exc}; a starter label map to complete: {starter} (then give the lab's model, marker set and "
        "setups in the config by hand: docs/first_recorded_subject.md)",
        exc.fits,
    )
    error.text = exc.text
    return error


def _template_text(setup: SubjectSetup) -> str:
    """The templates' fits, the one chosen and its markers and label map, as text."""
    t = setup.template
    return (
        f"\nMarker-set templates (required marker groups found, markers found):\n{format_fits(setup.fits)}\n"
        f"chosen: {t.name} ({t.title}) on {t.model}\n"
        f"  static trial markers: {len(setup.static_markers)}; walking trials: {len(setup.walking_markers)}"
        + (f"; static trial only (not tracked in walking): {', '.join(setup.static_only)}" if setup.static_only else "")
        + (
            f"\n  labels without a template marker (kept, not used): {', '.join(setup.unmapped)}"
            if setup.unmapped
            else ""
        )
        + (f"\n  label map: {len(setup.label_map)} row(s)" if len(setup.label_map) else "\n  label map: none needed")
        + "\n"
    )


def _written_subject_files(
    paths: Sequence[Path],
    kinds: Sequence[str],
    setup: SubjectSetup,
    summary: RecordingSummary,
    config_out: PathLike,
    mass_height: str,
) -> tuple[Path, ...]:
    """Write the template's model (a copy), marker set, ScaleTool setup, IK tasks, label map (when needed) and
    then the subject's config (``config_out``) beside it; returns the files written, the config last.

    Everything is built before anything is written; a file that would overwrite an input raises
    LoperInputError."""
    from loper_analysis.io.marker_templates import template_file
    from loper_analysis.io.osim import read_model, write_osim_object
    from loper_analysis.io.readers import read_bytes
    from loper_analysis.motion.marker_templates import (
        template_coordinate_map,
        template_marker_set,
        template_scale_tool,
    )

    t = setup.template
    folder = Path(config_out).parent
    model_path = template_file(t.model)
    model = read_model(model_path)
    coordinate_map = template_coordinate_map(t, model)
    marker_set = template_marker_set(t, setup.static_markers)
    tool = template_scale_tool(t, setup.static_markers, "marker_set.xml")
    files = {
        "model": str(folder / t.model),
        "marker_set": str(folder / "marker_set.xml"),
        "scale_setup": str(folder / "scale_setup.xml"),
        "ik_tasks": str(folder / "ik_tasks.tsv"),
        "config": str(config_out),
    }
    if len(setup.label_map):
        files["label_map"] = str(folder / "label_map.tsv")
    inputs = {p.resolve() for p in paths}
    clash = [f for f in files.values() if Path(f).resolve() in inputs]
    if clash:
        raise LoperInputError(f"{clash[0]}: would overwrite an input file; write the config to another folder")
    config_text = _subject_config_text(paths, kinds, setup, summary, files, coordinate_map, mass_height)
    model_bytes = read_bytes(model_path, "OpenSim model")
    write_bytes(files["model"], model_bytes, "OpenSim model")
    write_osim_object(marker_set, files["marker_set"], "marker set")
    write_osim_object(tool, files["scale_setup"], "ScaleTool setup")
    write_tsv(setup.ik_tasks, files["ik_tasks"])
    if "label_map" in files:
        write_tsv(setup.label_map, files["label_map"])
    write_text(config_out, config_text, "subject config")
    return tuple(
        Path(files[k]) for k in ("model", "marker_set", "scale_setup", "ik_tasks", "label_map", "config") if k in files
    )
