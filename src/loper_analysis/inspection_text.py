"""What ``loper-analysis inspect`` prints: a recording's summary (:mod:`loper_analysis.inspection`) and a match of
its labels to a model's markers (:mod:`loper_analysis.motion.label_matching`) as plain text; for a subject's
files, the template chosen (:func:`template_text`) and the subject's config (:func:`subject_config_text`).
"""

from __future__ import annotations

import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.inspection import MIN_MARKERS_PER_FRAME, RecordingSummary, yaml_flow
from loper_analysis.motion.lab_frame import (
    AXIS_NAMES,
    axis_name,
)
from loper_analysis.motion.label_matching import LabelMatch
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.motion.markers import rotate_markers
from loper_analysis.subject_setup import SubjectSetup, format_fits

__all__ = [
    "SubjectFiles",
    "format_label_match",
    "format_summary",
    "mass_height_line",
    "presence_text",
    "subject_config_text",
    "template_text",
]


def _xyz(v, digits: int = 3) -> str:
    return (
        "("
        + ", ".join(f"{float(x) + 0.0:.{digits}f}".replace("-0." + "0" * digits, "0." + "0" * digits) for x in v)
        + ")"
    )


def _ranges(frames: np.ndarray, limit: int = 6) -> str:
    """'0-56, 1050-1102' for sorted frame numbers (at most ``limit`` ranges, then '...')."""
    if frames.size == 0:
        return ""
    breaks = np.flatnonzero(np.diff(frames) != 1)
    starts = np.concatenate([[frames[0]], frames[breaks + 1]])
    ends = np.concatenate([frames[breaks], [frames[-1]]])
    parts = [f"{a}" if a == b else f"{a}-{b}" for a, b in zip(starts, ends)]
    more = len(parts) - limit
    return ", ".join(parts[:limit]) + (f", ... ({more} more ranges)" if more > 0 else "")


def _rotation_text(angles: Sequence[float]) -> str:
    return "[" + ", ".join(f"{a:g}" for a in angles) + "]"


def _model_axis(rotation_deg: Sequence[float], axis: int, sign: int) -> str:
    """Where the lab direction ``sign`` x axis ``axis`` points after the rotation (``"-X"`` ...)."""
    v = np.zeros(3)
    v[axis] = sign
    r = np.round(rotate_markers(v, rotation_deg))
    k = int(np.argmax(np.abs(r)))
    return axis_name(k, int(r[k]))


def format_summary(s: RecordingSummary) -> str:
    """The inspection of one recording as plain text (units stated on every line that has numbers)."""
    lines = (
        _header_lines(s) + _marker_lines(s) + _plate_lines(s) + _analog_lines(s) + _event_lines(s) + _lab_frame_lines(s)
    )
    return "\n".join(line.rstrip() for line in lines) + "\n"


def _header_lines(s: RecordingSummary) -> list[str]:
    """The file's rates (Hz), channel count and frame span (frames, s), then a blank line."""
    rate = s.point_rate_hz
    last = s.first_frame + s.n_frames - 1
    return [
        f"File {s.source}",
        f"  markers   {rate:g} Hz, POINT:UNITS {s.point_unit or '(none)'} (shown below in m)",
        f"  analogs   {s.analog_rate_hz:g} Hz ({round(s.analog_rate_hz / rate)} samples per frame), "
        f"{len(s.analog_labels)} channel(s)",
        f"  frames    {s.n_frames}, first frame {s.first_frame} (0-based) at {s.first_time_s:.3f} s, last frame "
        f"{last} at {last / rate:.3f} s; duration {s.duration_s:.3f} s ({s.n_frames} frames / {rate:g} Hz)",
        "",
    ]


def _marker_lines(s: RecordingSummary) -> list[str]:
    """The markers' table (presence in %, frames, longest gap in frames and s) and the sparse frames, then a
    blank line."""
    lines: list[str] = []
    m = s.markers
    width = max([len(lab) for lab in m["label"]] + [5])
    if len(m):
        lines.append(
            f"Markers: {len(m)} label(s); present = % of the {s.n_frames} frames; first and last present "
            "frame; longest gap = missing frames between them"
        )
        lines.append(f"  {'label':<{width}}  present %  first  last   longest gap")
    else:
        lines.append("Markers: none")
    for row in m.itertuples(index=False):
        if row.n_present == 0:
            lines.append(f"  {row.label:<{width}}  {0.0:9.1f}  never present")
            continue
        gap = "none" if row.longest_gap_frames == 0 else f"{row.longest_gap_frames} frames ({row.longest_gap_s:.3f} s)"
        lines.append(
            f"  {row.label:<{width}}  {row.present_pct:9.1f}  {int(row.first_present_frame):5d}  "
            f"{int(row.last_present_frame):5d}  {gap}"
        )
    n_sparse = s.sparse_frames.size
    lines.append(
        f"  frames with fewer than {MIN_MARKERS_PER_FRAME} markers: {n_sparse} of {s.n_frames}"
        + (
            f" (frames {_ranges(s.sparse_frames)}; {s.n_empty_frames} of them without any marker; "
            "inverse kinematics cannot use them)"
            if n_sparse
            else ""
        )
    )
    lines.append("")
    return lines


def _plate_lines(s: RecordingSummary) -> list[str]:
    """The force platforms: channels, corners, size and centre (m), normal, resting and peak vertical force (N),
    then a blank line."""
    lines: list[str] = []
    if s.plates:
        lines.append(
            f"Force platforms: {len(s.plates)} (forces on the body, lab frame; vertical = "
            f"{axis_name(s.vertical.axis, s.vertical.sign)})"
        )
    elif s.n_plates_declared:
        lines.append(f"Force platforms: {s.n_plates_declared} declared, not readable: {s.plate_problem}")
    else:
        lines.append("Force platforms: none (no FORCE_PLATFORM group; events then need events.grf_channels)")
    for p in s.plates:
        lines.append(f"  plate {p.number}: TYPE {p.type}, analog channels {', '.join(map(str, p.channels))}")
        lines.append("    corners (lab, m): " + " ".join(_xyz(c) for c in p.corners_m))
        lines.append(f"    size {p.side_lengths_m[0]:.3f} x {p.side_lengths_m[1]:.3f} m, centre {_xyz(p.centre_m)} m")
        order = (
            f"corners listed {p.corner_order} seen from above"
            if p.corner_order
            else "the plate does not face up or down"
        )
        lines.append(f"    normal from the corners (right-hand rule of their order): {_xyz(p.normal)}: {order}")
        if p.rest_vertical_n is None:
            lines.append("    resting vertical level: none (the plate is loaded throughout)")
            lines.append(f"    peak vertical force {p.peak_vertical_n:.1f} N at {p.peak_time_s:.3f} s (as read)")
        else:
            lines.append(
                f"    resting (unloaded) vertical level {p.rest_vertical_n:.1f} N; loaded (> 20 N above it) "
                f"{p.loaded_pct:.1f} % of the time"
            )
            lines.append(
                f"    peak vertical force {p.peak_vertical_n:.1f} N above rest at {p.peak_time_s:.3f} s "
                f"({p.peak_vertical_n + p.rest_vertical_n:.1f} N as read)"
            )
    lines.append("")
    return lines


def _analog_lines(s: RecordingSummary) -> list[str]:
    """The analog channels (rate in Hz; number, label, unit and owner of each), then a blank line."""
    lines = [f"Analog channels: {len(s.analog_labels)}, all at {s.analog_rate_hz:g} Hz"]
    if s.analog_labels:
        width = max(len(lab) for lab in s.analog_labels)
        for i, (lab, unit) in enumerate(zip(s.analog_labels, s.analog_units)):
            owner = s.channel_owner.get(i, "")
            lines.append(f"  {i + 1:3d}  {lab:<{width}}  {unit or '(no unit)':<8}" + (f"  {owner}" if owner else ""))
    lines.append("")
    return lines


def _event_lines(s: RecordingSummary) -> list[str]:
    """The file's events (context, label, time in s and frame), then a blank line."""
    lines: list[str] = []
    if len(s.events):
        lines.append(f"Events: {len(s.events)} (EVENT group; time on the file's clock, s)")
        for ev in s.events.itertuples(index=False):
            lines.append(
                f"  {ev.context:<8} {ev.label:<16} {ev.time_s:8.3f} s  (frame {round(ev.time_s * s.point_rate_hz)})"
            )
    else:
        lines.append("Events: none")
    lines.append("")
    return lines


def _lab_frame_lines(s: RecordingSummary) -> list[str]:
    """The lab frame: vertical axis, walking direction (m, m/s) and the suggested rotation (degrees)."""
    v, w = s.vertical, s.walking
    lines = ["Lab frame"]
    text = f"  vertical axis: {axis_name(v.axis, v.sign)} " + (
        "(assumed: neither plates nor markers tell)" if v.basis == "assumed" else f"(from the {v.basis})"
    )
    if v.marker_axis is not None:
        spread = ", ".join(f"{AXIS_NAMES[a]} {v.marker_spread_m[a]:.2f}" for a in range(3))
        agree = (
            "agree"
            if (v.marker_axis, v.marker_sign) == (v.axis, v.sign)
            else f"say {axis_name(v.marker_axis, v.marker_sign)}: check"
        )
        text += f"; the markers {agree} (median spread of a frame's markers, m: {spread})"
    lines.append(text)
    lines.append(_walking_line(s))
    lines.append(
        f"  suggested markers.lab_to_model_rotation_deg: {_rotation_text(s.rotation_deg)} (degrees about the "
        "fixed X, Y, Z: up -> model +Y)"
    )
    if w.axis is None:
        lines.append(
            "  (the facing direction is not known: check that the subject faces model +X, OpenSim's forward, "
            "after the rotation)"
        )
    elif tuple(s.rotation_forward_deg) == tuple(s.rotation_deg):
        lines.append("  (this trial then walks toward model +X, OpenSim's forward)")
    else:
        lines.append(
            f"  (this trial then walks toward model {_model_axis(s.rotation_deg, w.axis, w.sign)}; "
            f"{_rotation_text(s.rotation_forward_deg)} also turns its walking direction to model +X, "
            "OpenSim's forward)"
        )
    return lines


def _walking_line(s: RecordingSummary) -> str:
    """The walking direction's line: its axis, travel (m) and speed (m/s), or why it is not known."""
    w = s.walking
    if w.axis is None and not np.all(np.isfinite(w.travel_m)):
        return "  walking direction: unknown (no marker is present in two frames)"
    if w.axis is None:
        travel = ", ".join(f"{AXIS_NAMES[a]} {w.travel_m[a]:+.2f}" for a in range(3))
        return f"  walking direction: treadmill/standing (the markers do not travel; median travel, m: {travel})"
    return (
        f"  walking direction: {axis_name(w.axis, w.sign)} (the markers travel "
        f"{w.travel_m[w.axis]:+.2f} m along {AXIS_NAMES[w.axis]} at {w.speed_m_per_s:.2f} m/s)"
    )


def format_label_match(match: LabelMatch, model_name: str, n_model_markers: int) -> str:
    """The matching of a file's labels to a model's markers as plain text."""
    lines = [f"Labels and model markers ({model_name}: {n_model_markers} markers)"]
    lines.append(f"  matched: {len(match.pairs)} label(s)")
    if match.pairs:
        width = max(len(lab) for lab, _, _ in match.pairs)
        for label, marker, rule in match.pairs:
            lines.append(f"    {label:<{width}} -> {marker:<20} ({rule})")
    if match.ambiguous:
        lines.append(f"  ambiguous (left unmatched): {len(match.ambiguous)}")
        for label, candidates in match.ambiguous.items():
            lines.append(
                f"    {label}: {' or '.join(candidates)}"
                if len(candidates) > 1
                else f"    {label}: {candidates[0]} (wanted by more than one label)"
            )
    for title, names in (
        ("labels without a model marker", match.unmatched_labels),
        ("model markers no label provides", match.unprovided_markers),
    ):
        lines.append(f"  {title}: {len(names)}")
        if names:
            lines += textwrap.wrap(
                ", ".join(names), width=100, initial_indent="    ", subsequent_indent="    ", break_on_hyphens=False
            )
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- a subject's config


def presence_text(paths: Sequence[Path], kinds: Sequence[str], never: Sequence[Sequence[str]]) -> str:
    """Lines naming each trial's labels present in no frame (left out of the marker set or the IK tasks)."""
    lines = [
        f"  {p.name}: label(s) present in no frame, left out of the "
        + ("marker set and the scaling" if k == "static" else "IK tasks")
        + f": {', '.join(strip_subject_prefix(lab) for lab in n)}\n"
        for p, k, n in zip(paths, kinds, never)
        if n
    ]
    return "".join(lines)


@dataclass(frozen=True)
class SubjectFiles:
    """What a subject's config is written from (:func:`loper_analysis.stages.inspect.inspect_subject`): the files
    and their kinds, the template's setup, the first file's summary, the mass and height line, the marker
    cut-off (Hz) and its reason, whether a static trial is among the files, and each file's marker labels
    (no subject prefix)."""

    paths: list[Path]
    kinds: list[str]
    setup: SubjectSetup
    summary: RecordingSummary
    mass_height: str
    cutoff: tuple[float | None, str]
    has_static: bool
    trial_labels: list[list[str]]


def subject_config_text(
    subject: SubjectFiles, files: Mapping[str, str], coordinate_map: Mapping[str, Mapping], losses: Sequence[str]
) -> str:
    """The subject's config: every key with a comment (YAML)."""
    setup, summary, paths = subject.setup, subject.summary, subject.paths
    t = setup.template
    rotation = [float(a) for a in summary.rotation_deg]
    up = axis_name(summary.vertical.axis, summary.vertical.sign)
    lines = [
        f"# Settings of the subject recorded in {', '.join(str(p) for p in paths)}, written by loper-analysis inspect.",
        f"# Marker-set template: {t.name} ({t.title}) on {t.model}.",
        "# Add the subject to a sheet (subject, source: recorded, ...) named by `subjects:` below, then run",
        f"#   snakemake -j2 --configfile {files['config']}",
        f"# {subject.mass_height}",
        *[f"# scaling: {line}" for line in losses],
        "# subjects: lab/subjects.tsv          # the subject sheet (add this key)",
        "markers:",
        f"  lab_to_model_rotation_deg: {yaml_flow(rotation)}   # up {up} -> model +Y (each walking trial is turned "
        "to walk along model +X)",
    ]
    if "label_map" in files:
        lines.append(f"  label_map: {yaml_flow(files['label_map'])}   # lab label -> template marker")
    else:
        lines.append("  label_map: {}   # the labels every trial holds are the template's marker names")
    per_trial = {k.partition(":")[2]: v for k, v in files.items() if k.startswith("label_map:")}
    if per_trial:
        lines.append(
            f"  trial_label_maps: {yaml_flow(per_trial)}   # labels only that trial holds (a map naming a label "
            "its trial lacks is refused)"
        )
    cutoff, why = subject.cutoff
    lines += [
        "  filter:",
        f"    cutoff_hz: {'null' if cutoff is None else yaml_flow(cutoff)}   # walking trials' markers: {why}",
        "model:",
        f"  generic_model: {yaml_flow(files['model'])}   # {t.model} as OpenSim distributes it",
        f"  scale_setup: {yaml_flow(files['scale_setup'])}   # ScaleTool setup; names marker_set.xml beside it",
        "ik:",
        f"  ik_tasks: {yaml_flow(files['ik_tasks'])}   # markers of the walking trials and their weights"
        + (f"; not tracked (static trial only): {', '.join(setup.static_only)}" if setup.static_only else ""),
        "  coordinate_map:   # our angle -> model coordinate; each sign read from the model's kinematics",
    ]
    lines += [f"    {k}: {yaml_flow(dict(v))}" for k, v in coordinate_map.items()]
    feet = t.foot_markers
    lines += ["events:", f"  foot_markers: {yaml_flow(dict(feet))}   # heel markers: assign plate contacts to feet"]
    kinds_text = ", ".join(f"{p.stem} ({k})" for p, k in zip(paths, subject.kinds))
    lines.append(f"# trials: {kinds_text}")
    return "\n".join(lines) + "\n"


def mass_height_line(static_rec) -> str:
    """Where the subject's mass and height will come from when the sheet leaves them empty."""
    parts = []
    if static_rec is not None and static_rec.n_force_platforms:
        parts.append("mass: the static trial's force plates")
    elif static_rec is not None and "Bodymass" in static_rec.processing:
        parts.append(f"mass: {static_rec.processing['Bodymass']:.2f} kg (the file's PROCESSING:Bodymass)")
    if static_rec is not None and "Height" in static_rec.processing:
        parts.append(f"height: {static_rec.processing['Height'] / 1000:.3f} m (PROCESSING:Height)")
    return "Without mass or height in the sheet: " + ("; ".join(parts) or "give them in the sheet") + "."


def template_text(setup: SubjectSetup) -> str:
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
        + (
            "\n  label map: "
            + ", ".join(f"{lab}->{m}" for lab, m in zip(setup.label_map["label"], setup.label_map["marker"]))
            if len(setup.label_map)
            else "\n  label map: none needed"
        )
        + "\n"
    )
