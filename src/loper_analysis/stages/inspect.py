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

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import pandas as pd

from loper_analysis.errors import LoperInputError, one_line
from loper_analysis.filtering import CUTOFF_HZ
from loper_analysis.inspection import (
    RecordingSummary,
    config_snippet,
    marker_cutoff_hz,
    measurement_losses,
    recording_summary,
)
from loper_analysis.inspection_text import (
    SubjectFiles,
    format_label_match,
    format_summary,
    mass_height_line,
    presence_text,
    subject_config_text,
    template_text,
)
from loper_analysis.io.atomic import PathLike, write_bytes, write_text, write_tsv
from loper_analysis.io.c3d_parameter_section import read_parameter
from loper_analysis.motion.lab_frame import axis_name
from loper_analysis.motion.label_matching import LabelMatch, heel_markers, match_labels, starter_label_map
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.subject_setup import NoTemplateFits, StagedSubject, SubjectSetup, format_fits, trial_label_maps
from loper_analysis.timing import timed_io

if TYPE_CHECKING:
    from loper_analysis.io.c3d import C3DRecording

__all__ = [
    "Inspection",
    "StagedSubject",
    "SubjectInspection",
    "given_label_map",
    "inspect_c3d",
    "inspect_subject",
    "model_marker_names_of",
]


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
    """``POINT:UNITS`` of a C3D file as declared ("" when absent), from its parameter section."""
    units = read_parameter(path, "POINT", "UNITS")
    return units.split()[0] if isinstance(units, str) and units.split() else ""


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
        "generic_model": "scaled per subject with model.scale_setup, your ScaleTool setup"
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
        ``model.generic_model`` (with a model).

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
            + (", model.generic_model" if model is not None else "")
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


def given_label_map(label_map) -> tuple[dict[str, str], list[Path]]:
    """A lab's label map as ``inspect`` takes it, and the files it was read from.

    ``label_map`` is a mapping, a TSV (columns ``label``, ``marker``) or YAML file, a list of those (a later
    entry wins), or None. Unlike the pipeline's reader, a row whose marker is empty (a row of the starter map
    ``label_map_starter.tsv`` left empty) is skipped: the label keeps its name.

    Raises
    ------
    LoperInputError
        A missing or unreadable file, a table without the two columns, a label given twice in one file.
    """
    from loper_analysis.io.readers import read_tsv, read_yaml

    if label_map is None:
        return {}, []
    if isinstance(label_map, Mapping):
        return {str(k).strip(): str(v).strip() for k, v in label_map.items() if v is not None and str(v).strip()}, []
    if isinstance(label_map, (list, tuple)):
        merged, files = {}, []
        for part in label_map:
            entries, read = given_label_map(part)
            merged.update(entries)
            files += read
        return merged, files
    path = Path(label_map)
    if path.suffix.lower() in (".yaml", ".yml"):
        doc = read_yaml(path, "label map")
        if not isinstance(doc, Mapping):
            raise LoperInputError(f"{path}: a label map must be a YAML mapping 'label: marker'")
        pairs = list(doc.items())
    else:
        table = read_tsv(path, "label map", ("label", "marker"), dtype=str, keep_default_na=False)
        pairs = list(zip(table["label"], table["marker"]))
    out: dict[str, str] = {}
    for label, marker in pairs:
        label, marker = str(label).strip(), "" if marker is None else str(marker).strip()
        if not label or not marker:
            continue
        if label in out:
            raise LoperInputError(f"{path}: label map names label '{label}' twice")
        out[label] = marker
    return out, [path]


def _present_labels(rec: C3DRecording) -> tuple[list[str], list[str]]:
    """A recording's marker labels present in at least one frame, and those never present."""
    import numpy as np

    present = np.all(np.isfinite(rec.markers_m), axis=2).any(axis=0)
    labels = list(rec.marker_labels)
    return [lab for lab, p in zip(labels, present) if p], [lab for lab, p in zip(labels, present) if not p]


def inspect_subject(
    c3d_paths: Sequence[PathLike],
    config_out: PathLike | None = None,
    static_name: str = "static",
    label_map=None,
    cutoff_hz: float | None = CUTOFF_HZ,
    check: Callable[[StagedSubject], str] | None = None,
) -> SubjectInspection:
    """Inspect a subject's C3D files, choose the marker-set template that fits their labels, and (``config_out``)
    write the subject's config with the files it names beside it.

    Each file's kind comes from its name: ``static_name`` (``study.static``) is the static trial, every other
    file a walking trial. Labels present in no frame of a trial count as absent from it. The lab's label map
    (``label_map``: :func:`given_label_map`) renames labels before they are matched. The template
    (:func:`loper_analysis.subject_setup.subject_setup`) gives the label map, the marker set of the static
    trial's markers, a ScaleTool setup naming it (a pair of a measurement whose marker the static trial lacks
    is left out, and a measurement left without a pair is reported), the walking trials' IK tasks (markers of
    the static trial present in every walking trial) and the heel markers; the coordinate map's signs are read
    from the template's model (:func:`loper_analysis.motion.marker_templates.template_coordinate_map`); the
    walking trials' low-pass cut-off is :func:`loper_analysis.inspection.marker_cutoff_hz` of ``cutoff_hz``.

    Written beside ``config_out`` (paths in the config as given, so relative ones count from where snakemake
    runs): the model (a copy), ``marker_set.xml``, ``scale_setup.xml``, ``ik_tasks.tsv``, ``label_map.tsv``
    (when a label differs from its marker), then the config. Everything is built in a scratch folder first
    and ``check`` (the command line's dry run: scaling the static trial) runs on it; only when it passes are
    the files put in place.

    Parameters
    ----------
    c3d_paths : sequence of path-like
        The subject's C3D files.
    config_out : path-like, optional
        The subject's config; None: nothing is written.
    static_name : str
        The static trial's name (``study.static``).
    label_map : mapping, path-like or list, optional
        The lab's label map (``markers.label_map`` or ``--label-map``).
    cutoff_hz : float or None
        The configured marker low-pass cut-off (Hz, ``markers.filter.cutoff_hz``); None: no filter.
    check : callable, optional
        Called with the :class:`StagedSubject`; returns a line for the report or raises LoperInputError
        (nothing is written then).

    Raises
    ------
    LoperInputError
        A missing or unreadable file; an output path equal to an input (a C3D file or the label map); the
        check failing (nothing written).
    loper_analysis.subject_setup.NoTemplateFits
        The labels fit no template: the message lists what was and was not mapped; with ``config_out`` a
        starter map (``label_map_starter.tsv``: every label, the template's marker where one was found) is
        written beside it and nothing else.
    """
    from loper_analysis.stages.templates import read_templates
    from loper_analysis.subject_setup import subject_setup

    paths = [Path(p) for p in c3d_paths]
    given, map_files = given_label_map(label_map)
    if config_out is not None and any(Path(config_out).resolve() == p.resolve() for p in [*paths, *map_files]):
        raise LoperInputError(f"{config_out}: the config would overwrite an input file")
    kinds = [_trial_kind(p, static_name) for p in paths]
    recs, summaries, text = _recordings_text(paths)
    present = [_present_labels(r) for r in recs]
    text += presence_text(paths, kinds, [n for _, n in present])
    static = next((r for r, k in zip(recs, kinds) if k == "static"), None)
    static_labels = next((p for p, k in zip(present, kinds) if k == "static"), (None,))[0]
    walking = [p for p, k in zip(present, kinds) if k == "walking"]
    source = ", ".join(str(p) for p in paths)
    if given:
        text += f"  label map given: {len(given)} row(s) ({', '.join(str(f) for f in map_files) or 'inline'})\n"
    try:
        setup = subject_setup(static_labels, [w for w, _ in walking], read_templates(), source, given)
    except NoTemplateFits as exc:
        exc.text = (
            text + f"\nMarker-set templates (required marker groups found, markers found):\n{format_fits(exc.fits)}\n"
        )
        if config_out is not None:
            raise _starter_map_error(exc, recs, config_out) from None
        raise
    text += template_text(setup)
    if static is None:
        text += "  no static trial among the files: its markers were taken from the first walking trial\n"
    mass_height = mass_height_line(static)
    text += f"  {mass_height}\n"
    cutoff = marker_cutoff_hz(cutoff_hz, [r.point_rate_hz for r, k in zip(recs, kinds) if k == "walking"])
    text += f"  markers.filter.cutoff_hz: {cutoff[0]} ({cutoff[1]})\n"
    if config_out is None:
        return SubjectInspection(summaries, setup, text)

    labels = [[strip_subject_prefix(lab) for lab in r.marker_labels] for r in recs]
    subject = SubjectFiles(paths, kinds, setup, summaries[0], mass_height, cutoff, static is not None, labels)
    written, more = _written_subject_files(subject, config_out, check)
    text += more + "\n" + "\n".join(f"wrote {w}" for w in written) + "\n"
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
    labels = list(dict.fromkeys(strip_subject_prefix(lab) for r in recs for lab in r.marker_labels))
    starter = Path(config_out).parent / "label_map_starter.tsv"
    write_tsv(pd.DataFrame({"label": labels, "marker": [exc.mapped.get(lab, "") for lab in labels]}), starter)
    error = NoTemplateFits(
        f"{exc}; a starter label map to complete: {starter} (fill in the template marker of each label you can, "
        "leave the others empty, then run inspect again with --label-map "
        f"{starter} or markers.label_map: {starter} in a --configfile; a marker set that is no template's needs "
        "the lab's model, marker set and setups in the config by hand: docs/first_recorded_subject.md)",
        exc.fits,
        exc.mapped,
    )
    error.text = exc.text
    return error


def _measurement_names(tool) -> list[str]:
    """The measurements of a ScaleTool's model scaler."""
    ms = tool.getModelScaler().getMeasurementSet()
    return [ms.get(i).getName() for i in range(ms.getSize())]


def _staged_files(subject: SubjectFiles, folder: Path, names: Mapping[str, str]) -> tuple[dict[str, Path], list[str]]:
    """Write the template's model (a copy), marker set, ScaleTool setup, IK tasks, label map (when needed) and
    the config into ``folder``, the config naming the files by their final paths ``names``; returns the files
    staged and the scaling's losses (:func:`loper_analysis.inspection.measurement_losses`)."""
    from loper_analysis.io.marker_templates import template_file
    from loper_analysis.io.osim import read_model, write_osim_object
    from loper_analysis.io.readers import read_bytes
    from loper_analysis.motion.marker_templates import (
        template_coordinate_map,
        template_marker_set,
        template_scale_tool,
    )

    setup = subject.setup
    t = setup.template
    model_path = template_file(t.model)
    model = read_model(model_path)
    coordinate_map = template_coordinate_map(t, model)
    marker_set = template_marker_set(t, setup.static_markers, model)
    tool = template_scale_tool(t, setup.static_markers, "marker_set.xml")
    losses = measurement_losses(t.measurements, t.marker_names, setup.static_markers, _measurement_names(tool))
    staged = {key: folder / Path(name).name for key, name in names.items()}
    write_bytes(staged["model"], read_bytes(model_path, "OpenSim model"), "OpenSim model")
    write_osim_object(marker_set, staged["marker_set"], "marker set")
    write_osim_object(tool, staged["scale_setup"], "ScaleTool setup")
    write_tsv(setup.ik_tasks, staged["ik_tasks"])
    for key, table in trial_label_maps(
        subject.setup.label_map, [p.stem for p in subject.paths], subject.trial_labels
    ).items():
        write_tsv(table, staged[key])
    write_text(staged["config"], subject_config_text(subject, names, coordinate_map, losses), "subject config")
    return staged, losses


def _written_subject_files(
    subject: SubjectFiles, config_out: PathLike, check: Callable[[StagedSubject], str] | None
) -> tuple[tuple[Path, ...], str]:
    """Build the subject's files in a scratch folder (:func:`_staged_files`), run ``check`` on them and, when
    it passes, put them beside ``config_out`` (the config last); returns the files written and the text of the
    losses and the check. A file that would overwrite an input, a failing check or a failing write raises
    LoperInputError with nothing of this run left in place."""
    import tempfile

    from loper_analysis.io.readers import read_bytes

    setup = subject.setup
    folder = Path(config_out).parent
    names = {
        "model": str(folder / setup.template.model),
        "marker_set": str(folder / "marker_set.xml"),
        "scale_setup": str(folder / "scale_setup.xml"),
        "ik_tasks": str(folder / "ik_tasks.tsv"),
        "config": str(config_out),
    }
    maps = trial_label_maps(subject.setup.label_map, [p.stem for p in subject.paths], subject.trial_labels)
    for key in maps:
        names[key] = str(folder / ("label_map.tsv" if key == "label_map" else f"label_map_{key[10:]}.tsv"))
    order = ["model", "marker_set", "scale_setup", "ik_tasks", *maps, "config"]
    names = {k: names[k] for k in order}
    inputs = {p.resolve() for p in subject.paths}
    clash = [f for f in names.values() if Path(f).resolve() in inputs]
    if clash:
        raise LoperInputError(f"{clash[0]}: would overwrite an input file; write the config to another folder")
    with tempfile.TemporaryDirectory(prefix="loper-inspect-") as scratch:
        staged, losses = _staged_files(subject, Path(scratch), names)
        text = "".join(f"  scaling: {line}\n" for line in losses)
        if check is not None:
            static = next((p for p, k in zip(subject.paths, subject.kinds) if k == "static"), None)
            per_trial = {
                str(p): tuple(staged[k] for k in ("label_map", f"label_map:{p.stem}") if k in staged)
                for p in subject.paths
            }
            text += check(
                StagedSubject(
                    staged,
                    static if subject.has_static else None,
                    tuple(p for p, k in zip(subject.paths, subject.kinds) if k == "walking"),
                    per_trial,
                    tuple(float(a) for a in subject.summary.rotation_deg),
                    subject.cutoff[0],
                    setup,
                )
            )
        contents = {k: read_bytes(staged[k], "staged file") for k in order}
    _put_in_place({Path(names[k]): contents[k] for k in order})
    return tuple(Path(names[k]) for k in order), text


def _put_in_place(contents: Mapping[Path, bytes]) -> None:
    """Write each file in order (atomically); when one fails, the files this call wrote are put back as they
    were (or removed) before the error goes on."""
    before = {p: p.read_bytes() if p.is_file() else None for p in contents}
    done = []
    try:
        for path, data in contents.items():
            write_bytes(path, data, path.name)
            done.append(path)
    except Exception:
        for path in done:
            if before[path] is None:
                path.unlink(missing_ok=True)
            else:
                write_bytes(path, before[path], path.name)
        raise
