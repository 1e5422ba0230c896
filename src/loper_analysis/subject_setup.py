"""A subject's settings from its files: the marker-set template that fits its labels, and what follows from it.

``loper-analysis inspect`` with a subject's static and walking trials and no model
(:func:`loper_analysis.stages.inspect.inspect_subject`) asks this module which template fits the labels
(:func:`subject_setup`): every template's required marker groups are checked against the labels of all
files (:func:`loper_analysis.motion.marker_templates.template_fit`); the template with the largest share
of its groups found wins (then the most markers). From it follow the label map (the lab's labels whose
name differs from the template's marker), the markers of the static trial (the marker set, the scaling
pairs, the marker placer's tasks) and those of every walking trial (the IK tasks: a marker of the static
trial only is not tracked in walking), and the heel markers.

A lab's label map (``markers.label_map``, or ``inspect --label-map``) renames the labels before they are
matched: a label it names is matched under its new name (a template marker's name matches at once), and the
label map written maps the lab's own label to the template marker found. A row without a marker (a starter
map's row left empty) changes nothing.

When no template fits, :class:`NoTemplateFits` says what could and could not be mapped.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.motion.marker_templates import (
    MarkerTemplate,
    TemplateFit,
    derived_markers,
    template_fit,
    template_ik_tasks,
)

__all__ = ["NoTemplateFits", "StagedSubject", "SubjectSetup", "format_fits", "subject_setup", "trial_label_maps"]


class NoTemplateFits(LoperInputError):
    """No template's required markers are all among the labels; ``fits`` holds every template's fit (best first)."""

    def __init__(self, message: str, fits: Sequence[TemplateFit], mapped: Mapping[str, str] | None = None):
        super().__init__(message)
        self.fits = list(fits)
        self.text = ""  # what the inspection printed before it stopped
        #: the lab's label (no subject prefix) -> the closest template's marker, for each label mapped
        self.mapped = dict(mapped or {})


@dataclass(frozen=True)
class SubjectSetup:
    """What a subject's files and the fitting template give (:func:`subject_setup`).

    Attributes
    ----------
    template : MarkerTemplate
    fits : list of TemplateFit
        Every template's fit to the labels of all files, best first (``fits[0]`` is the template's).
    label_map : pandas.DataFrame
        Columns ``label``, ``marker``: the labels (no subject prefix) whose name differs from their marker.
    static_markers : tuple of str
        Template markers the static trial provides (the knee marker of a knee alignment device included).
    walking_markers : tuple of str
        Template markers every walking trial provides.
    static_only : tuple of str
        Template markers of the static trial that a walking trial lacks (not tracked in walking).
    unmapped : tuple of str
        Labels that are no template marker (kept in the trials, not used).
    ik_tasks : pandas.DataFrame
        The walking trials' IK tasks (:func:`loper_analysis.motion.marker_templates.template_ik_tasks`).
    """

    template: MarkerTemplate
    fits: list[TemplateFit]
    label_map: pd.DataFrame
    static_markers: tuple[str, ...]
    walking_markers: tuple[str, ...]
    static_only: tuple[str, ...]
    unmapped: tuple[str, ...]
    ik_tasks: pd.DataFrame


def _markers_of(labels: Sequence[str], to_marker: Mapping[str, str], template: MarkerTemplate) -> list[str]:
    """Template markers a file's labels provide (derived ones included)."""
    names = [to_marker[strip_subject_prefix(lab)] for lab in labels if strip_subject_prefix(lab) in to_marker]
    names += list(derived_markers(names, template.side_prefix))
    known = set(template.marker_names)
    return list(dict.fromkeys(n for n in names if n in known))


def subject_setup(
    static_labels: Sequence[str] | None,
    walking_labels: Sequence[Sequence[str]],
    templates: Mapping[str, MarkerTemplate],
    source: str = "",
    label_map: Mapping[str, str] | None = None,
) -> SubjectSetup:
    """The template that fits a subject's labels, its label map and the markers of each kind of trial.

    Parameters
    ----------
    static_labels : sequence of str or None
        The static trial's marker labels (None: no static trial among the files).
    walking_labels : sequence of sequences of str
        Each walking trial's marker labels.
    templates : mapping
        Name -> :class:`~loper_analysis.motion.marker_templates.MarkerTemplate`.
    source : str
        The files, for messages.
    label_map : mapping of str to str, optional
        The lab's label map {label: name}, applied before matching (subject prefix stripped; rows whose name
        is empty are left out).

    Raises
    ------
    NoTemplateFits
        No template finds all its required groups: the message lists, for the best template, the markers
        found and the groups missing, and the labels left without a marker.
    """
    given = {str(k).strip(): str(v).strip() for k, v in (label_map or {}).items() if str(v or "").strip()}

    def renamed(label: str) -> str:
        bare = strip_subject_prefix(label)
        return given.get(bare, bare)

    every = list(dict.fromkeys([*(static_labels or []), *(lab for labels in walking_labels for lab in labels)]))
    bare = list(dict.fromkeys(strip_subject_prefix(lab) for lab in every))
    fits = sorted(
        (template_fit([renamed(lab) for lab in bare], t) for t in templates.values()),
        key=lambda f: (-f.share, -len(f.found), f.template.name),
    )
    if not fits:
        raise LoperInputError(f"{source}: no marker-set template to choose from")
    best = fits[0]
    by_name = {name: marker for name, marker, _ in best.match.pairs}
    to_marker = {lab: by_name[renamed(lab)] for lab in bare if renamed(lab) in by_name}
    if not best.fits:
        left = [lab for lab in bare if lab not in to_marker]
        raise NoTemplateFits(
            f"{source}: the labels fit no marker-set template; closest: {best.template.name} "
            f"({best.template.title}), {len(best.template.required) - len(best.missing_groups)} of "
            f"{len(best.template.required)} required markers found; missing: "
            + ", ".join(" or ".join(g) for g in best.missing_groups)
            + f"; labels mapped: {', '.join(f'{lab}->{m}' for lab, m in to_marker.items()) or 'none'}"
            + f"; labels left without a marker: {', '.join(left) or 'none'}",
            fits,
            to_marker,
        )
    template = best.template
    static = _markers_of(static_labels or (walking_labels[0] if walking_labels else []), to_marker, template)
    walking = [_markers_of(labels, to_marker, template) for labels in walking_labels]
    in_walking = [m for m in template.marker_names if all(m in w for w in walking)] if walking else static
    if static_labels is not None:  # a marker the model (the static trial's marker set) lacks cannot be tracked
        in_walking = [m for m in in_walking if m in set(static)]
    known = set(template.marker_names)
    unmapped = tuple(lab for lab in bare if to_marker.get(lab) not in known)
    rows = [(lab, marker) for lab, marker in to_marker.items() if lab != marker]
    return SubjectSetup(
        template=template,
        fits=fits,
        label_map=pd.DataFrame(rows, columns=["label", "marker"], dtype=object),
        static_markers=tuple(static),
        walking_markers=tuple(in_walking),
        static_only=tuple(m for m in static if m not in set(in_walking)),
        unmapped=unmapped,
        ik_tasks=template_ik_tasks(template, in_walking),
    )


def format_fits(fits: Sequence[TemplateFit]) -> str:
    """Lines giving each template's fit: required groups found, markers found, what is missing."""
    lines = []
    for f in fits:
        missing = ", ".join(" or ".join(g) for g in f.missing_groups) or "nothing"
        lines.append(
            f"  {f.template.name:<12} {len(f.template.required) - len(f.missing_groups)} of "
            f"{len(f.template.required)} required, {len(f.found)} of {len(f.template.markers)} markers; "
            f"missing {missing}"
        )
    return "\n".join(lines)


@dataclass(frozen=True)
class StagedSubject:
    """A subject's files built in a scratch folder, not yet in place: what a dry run (``check`` of
    :func:`loper_analysis.stages.inspect.inspect_subject`) reads.

    Attributes
    ----------
    files : dict of str to Path
        ``model``, ``marker_set``, ``scale_setup``, ``ik_tasks``, the label maps and ``config``, each in the
        scratch folder under its final name (the setup names the marker set beside it).
    static_c3d : Path or None
        The static trial.
    walking_c3d : tuple of Path
        The walking trials.
    label_maps : dict of str to tuple of Path
        Each trial's file (as given) -> its label maps in the scratch folder, merged in order.
    rotation_deg : tuple of float
        ``markers.lab_to_model_rotation_deg`` written (degrees).
    cutoff_hz : float or None
        ``markers.filter.cutoff_hz`` written (Hz).
    setup : SubjectSetup
        The template and what follows.
    """

    files: dict[str, Path]
    static_c3d: Path | None
    walking_c3d: tuple[Path, ...]
    label_maps: dict[str, tuple[Path, ...]]
    rotation_deg: tuple[float, float, float]
    cutoff_hz: float | None
    setup: SubjectSetup


def trial_label_maps(
    label_map: pd.DataFrame, trials: Sequence[str], trial_labels: Sequence[Sequence[str]]
) -> dict[str, pd.DataFrame]:
    """A label map's rows split by the trials holding their labels (the pipeline refuses a map naming a label its
    trial lacks).

    Parameters
    ----------
    label_map : pandas.DataFrame
        Columns ``label``, ``marker``.
    trials : sequence of str
        The trials' names.
    trial_labels : sequence of sequences of str
        Each trial's labels (no subject prefix).

    Returns
    -------
    dict of str to pandas.DataFrame
        ``label_map``: the rows of labels every trial holds; ``label_map:{trial}``: the rows of labels only some
        trials hold, for each trial holding one (``markers.trial_label_maps``). Empty maps are left out.
    """
    held = [set(labels) for labels in trial_labels]
    everywhere = [all(lab in h for h in held) for lab in label_map["label"]]
    out = {"label_map": label_map[everywhere]}
    for trial, h in zip(trials, held):
        out[f"label_map:{trial}"] = label_map[[not e and lab in h for lab, e in zip(label_map["label"], everywhere)]]
    return {k: v.reset_index(drop=True) for k, v in out.items() if len(v)}
