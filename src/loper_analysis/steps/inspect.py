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

from dataclasses import dataclass
from pathlib import Path

from loper_analysis.errors import LoperInputError, one_line
from loper_analysis.inspection import (
    RecordingSummary,
    config_snippet,
    format_label_match,
    format_summary,
    recording_summary,
)
from loper_analysis.io.atomic import PathLike, write_text, write_tsv
from loper_analysis.io.c3d_parameters import param_strings
from loper_analysis.io.timing import library_import, timed_io
from loper_analysis.motion.lab_frame import axis_name
from loper_analysis.motion.label_matching import LabelMatch, heel_markers, match_labels, starter_label_map
from loper_analysis.motion.marker_names import strip_subject_prefix

__all__ = ["Inspection", "inspect_c3d", "model_marker_names_of"]


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
    from loper_analysis.io.c3d import read_c3d
    from loper_analysis.io.force_platforms import read_force_platforms

    if model_osim is None and marker_set_xml is not None:
        raise LoperInputError(f"{marker_set_xml}: a marker set is added to a model: give --model as well")
    if model_osim is None and label_map_out is not None:
        raise LoperInputError(f"{label_map_out}: a label map needs a model to match the labels to: give --model")
    path = Path(c3d_path)
    rec = read_c3d(path)
    plates, problem = [], ""
    if rec.n_force_platforms:
        try:
            plates = read_force_platforms(path)
        except LoperInputError as exc:
            problem = one_line(exc)
    summary = recording_summary(rec, plates, point_unit=_point_unit(path), plate_problem=problem)
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
