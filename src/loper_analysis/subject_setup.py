"""A subject's settings from its files: the marker-set template that fits its labels, and what follows from it.

``loper-analysis inspect`` with a subject's static and walking trials and no model
(:func:`loper_analysis.steps.inspect.inspect_subject`) asks this module which template fits the labels
(:func:`subject_setup`): every template's required marker groups are checked against the labels of all
files (:func:`loper_analysis.motion.marker_templates.template_fit`); the template with the largest share
of its groups found wins (then the most markers). From it follow the label map (the lab's labels whose
name differs from the template's marker), the markers of the static trial (the marker set, the scaling
pairs, the marker placer's tasks) and those of every walking trial (the IK tasks: a marker of the static
trial only is not tracked in walking), and the heel markers.

When no template fits, :class:`NoTemplateFits` says what could and could not be mapped.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.label_matching import starter_label_map
from loper_analysis.motion.marker_names import strip_subject_prefix
from loper_analysis.motion.marker_templates import (
    MarkerTemplate,
    TemplateFit,
    derived_markers,
    template_fit,
    template_ik_tasks,
)

__all__ = ["NoTemplateFits", "SubjectSetup", "subject_setup", "format_fits"]


class NoTemplateFits(LoperInputError):
    """No template's required markers are all among the labels; ``fits`` holds every template's fit (best first)."""

    def __init__(self, message: str, fits: Sequence[TemplateFit]):
        super().__init__(message)
        self.fits = list(fits)
        self.text = ""  # what the inspection printed before it stopped


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

    Raises
    ------
    NoTemplateFits
        No template finds all its required groups: the message lists, for the best template, the markers
        found and the groups missing, and the labels left without a marker.
    """
    every = list(dict.fromkeys([*(static_labels or []), *(lab for labels in walking_labels for lab in labels)]))
    fits = sorted(
        (template_fit(every, t) for t in templates.values()),
        key=lambda f: (-f.share, -len(f.found), f.template.name),
    )
    if not fits:
        raise LoperInputError(f"{source}: no marker-set template to choose from")
    best = fits[0]
    if not best.fits:
        matched = {strip_subject_prefix(lab) for lab, _, _ in best.match.pairs}
        left = [strip_subject_prefix(lab) for lab in every if strip_subject_prefix(lab) not in matched]
        raise NoTemplateFits(
            f"{source}: the labels fit no marker-set template; closest: {best.template.name} "
            f"({best.template.title}), {len(best.template.required) - len(best.missing_groups)} of "
            f"{len(best.template.required)} required markers found; missing: "
            + ", ".join(" or ".join(g) for g in best.missing_groups)
            + f"; labels mapped: {', '.join(f'{lab}->{m}' for lab, m, _ in best.match.pairs) or 'none'}"
            + f"; labels left without a marker: {', '.join(left) or 'none'}",
            fits,
        )
    template = best.template
    to_marker = {strip_subject_prefix(lab): marker for lab, marker, _ in best.match.pairs}
    static = _markers_of(static_labels or (walking_labels[0] if walking_labels else []), to_marker, template)
    walking = [_markers_of(labels, to_marker, template) for labels in walking_labels]
    in_walking = [m for m in template.marker_names if all(m in w for w in walking)] if walking else static
    known = set(template.marker_names)
    unmapped = tuple(
        strip_subject_prefix(lab) for lab in every if to_marker.get(strip_subject_prefix(lab)) not in known
    )
    return SubjectSetup(
        template=template,
        fits=fits,
        label_map=starter_label_map(best.match),
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
