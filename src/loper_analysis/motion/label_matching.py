"""Matching a lab's marker labels to a model's markers by name, with a table of landmark synonyms.

Used by ``loper-analysis inspect`` (:mod:`loper_analysis.inspection`,
:mod:`loper_analysis.stages.inspect`) to pair a C3D file's labels with an
OpenSim model's markers and to write a starter label map from the pairs.

Label matching (:func:`match_labels`)
    Lab labels (subject prefix stripped,
    :func:`loper_analysis.motion.marker_names.strip_subject_prefix`) are matched
    to model markers in four rounds, each on the labels and markers still
    free: the same name; the same name ignoring case; the same name
    ignoring case and every character but letters and digits (``R.ASIS``,
    ``R_ASIS``, ``RASIS``); the same side (a leading ``L``/``R``,
    ``Left``/``Right``, or a trailing ``_l``/``_r``) and landmark in
    :data:`LANDMARK_SYNONYMS`, the package's synonym table
    (``templates/label_synonyms.yaml``, read by :mod:`loper_analysis.io.label_synonyms`). A label with more
    than one candidate marker, or two labels wanting one marker, is ambiguous and stays unmatched.

Label map (:func:`starter_label_map`)
    The matched labels whose name differs from their marker, as the rows
    of a ``markers.label_map`` file.

Heel markers (:func:`heel_markers`)
    The one heel marker of each side among a list of names (spellings of
    :data:`LANDMARK_SYNONYMS`), for ``events.foot_markers``.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import pandas as pd

from loper_analysis.io.label_synonyms import LANDMARK_SYNONYMS
from loper_analysis.motion.marker_names import strip_subject_prefix

__all__ = [
    "LANDMARK_SYNONYMS",
    "LabelMatch",
    "heel_markers",
    "landmark_indices",
    "match_labels",
    "side_landmark_indices",
    "starter_label_map",
]

_SPELLING_TO_LANDMARK = {s: name for name, spellings in LANDMARK_SYNONYMS.items() for s in spellings}
_NOT_ALNUM = re.compile(r"[^0-9a-z]")
_SIDE_SUFFIX = re.compile(r"[._\-\s]([lr])$", re.IGNORECASE)
#: Rounds of :func:`match_labels`, in order.
_RULES = ("exact", "case", "punctuation", "synonym")


@dataclass(frozen=True)
class LabelMatch:
    """Lab labels matched to model markers (:func:`match_labels`).

    Attributes
    ----------
    pairs : tuple of (label, marker, rule)
        The file's label (as in the file), the model marker, and the round
        that matched them (``exact``, ``case``, ``punctuation``, ``synonym``), in file order.
    unmatched_labels : tuple of str
        Labels (as in the file) without a marker, ambiguous ones included.
    ambiguous : dict of str to tuple of str
        Label -> the markers it could have been (or the one marker two labels wanted).
    unprovided_markers : tuple of str
        Model markers no label provides, in model order.
    """

    pairs: tuple[tuple[str, str, str], ...]
    unmatched_labels: tuple[str, ...]
    ambiguous: dict[str, tuple[str, ...]]
    unprovided_markers: tuple[str, ...]


def _normalised(name: str) -> str:
    return _NOT_ALNUM.sub("", str(name).lower())


def _landmarks(name: str) -> set[tuple[str | None, str]]:
    """(side, landmark) readings of a name: unsided, leading L/R or Left/Right, trailing _l/_r."""
    flat = _normalised(name)
    readings: list[tuple[str | None, str]] = [(None, flat)]
    for word, side in (("left", "l"), ("right", "r")):
        if flat.startswith(word):
            readings.append((side, flat[len(word) :]))
    if flat[:1] in ("l", "r"):
        readings.append((flat[0], flat[1:]))
    suffix = _SIDE_SUFFIX.search(str(name).strip())
    if suffix:
        readings.append((suffix.group(1).lower(), flat[:-1]))
    return {(side, _SPELLING_TO_LANDMARK[rest]) for side, rest in readings if rest in _SPELLING_TO_LANDMARK}


def _keys(name: str, rule: str) -> set:
    if rule == "exact":
        return {name}
    if rule == "case":
        return {name.lower()}
    if rule == "punctuation":
        flat = _normalised(name)
        return {flat} if flat else set()
    return _landmarks(name)


def match_labels(labels: Sequence[str], model_markers: Sequence[str]) -> LabelMatch:
    """Match a file's marker labels to a model's markers by name (rules in the module notes).

    Parameters
    ----------
    labels : sequence of str
        The file's labels, as in the file (a subject prefix ``Name:`` is stripped for matching).
    model_markers : sequence of str
        The model's marker names (repeats are ignored).

    Returns
    -------
    LabelMatch
        Pairs in file order; unmatched and ambiguous labels; model markers no label provides.
    """
    labels = [str(lab) for lab in labels]
    names = [strip_subject_prefix(lab) for lab in labels]
    markers = list(dict.fromkeys(str(m) for m in model_markers))
    matched: dict[int, tuple[str, str]] = {}
    ambiguous: dict[int, tuple[str, ...]] = {}
    for rule in _RULES:
        free = [m for m in markers if m not in {mk for mk, _ in matched.values()}]
        by_key: dict = {}
        for m in free:
            for key in _keys(m, rule):
                by_key.setdefault(key, []).append(m)
        wanted: dict[int, list[str]] = {}
        for i, name in enumerate(names):
            if i in matched or i in ambiguous:
                continue
            candidates = list(dict.fromkeys(m for key in _keys(name, rule) for m in by_key.get(key, ())))
            if candidates:
                wanted[i] = candidates
        demand: dict[str, int] = {}
        for candidates in wanted.values():
            if len(candidates) == 1:
                demand[candidates[0]] = demand.get(candidates[0], 0) + 1
        for i, candidates in wanted.items():
            if len(candidates) == 1 and demand[candidates[0]] == 1:
                matched[i] = (candidates[0], rule)
            else:
                ambiguous[i] = tuple(candidates)
    taken = {m for m, _ in matched.values()}
    return LabelMatch(
        pairs=tuple((labels[i], *matched[i]) for i in sorted(matched)),
        unmatched_labels=tuple(labels[i] for i in range(len(labels)) if i not in matched),
        ambiguous={labels[i]: ambiguous[i] for i in sorted(ambiguous)},
        unprovided_markers=tuple(m for m in markers if m not in taken),
    )


def starter_label_map(match: LabelMatch) -> pd.DataFrame:
    """The label map rows of a match: columns ``label`` (prefix stripped), ``marker``; only names that differ.

    A label already named like its marker needs no row. The table is what
    :func:`loper_analysis.io.readers.read_label_map` reads from a TSV.

    Parameters
    ----------
    match : LabelMatch
        As :func:`match_labels` returns it.

    Returns
    -------
    pandas.DataFrame
        Columns ``label``, ``marker`` (object dtype), one row per pair whose names differ, in file order.
    """
    rows = [
        (strip_subject_prefix(label), marker)
        for label, marker, _ in match.pairs
        if strip_subject_prefix(label) != marker
    ]
    return pd.DataFrame(rows, columns=["label", "marker"], dtype=object)


def landmark_indices(names: Sequence[str], landmarks: Sequence[str]) -> list[int]:
    """Indices of the names that spell one of ``landmarks`` (keys of :data:`LANDMARK_SYNONYMS`), either side."""
    wanted = set(landmarks)
    return [i for i, name in enumerate(names) if any(lm in wanted for _, lm in _landmarks(str(name)))]


def side_landmark_indices(names: Sequence[str], landmarks: Sequence[str], side: str) -> list[int]:
    """Indices of the names that spell one of ``landmarks`` (keys of :data:`LANDMARK_SYNONYMS`) of one side
    (``"left"`` or ``"right"``: a leading ``L``/``Left``, ``R``/``Right``, or a trailing ``_l``/``_r``)."""
    wanted, s = set(landmarks), str(side)[:1].lower()
    return [i for i, name in enumerate(names) if any(lm in wanted and sd == s for sd, lm in _landmarks(str(name)))]


def heel_markers(names: Sequence[str]) -> dict[str, str] | None:
    """``{"left": ..., "right": ...}``: the one heel marker of each side among ``names``; None unless both are unique.

    Heel spellings are those of :data:`LANDMARK_SYNONYMS` (``LHEE``, ``L.Heel``, ``LCAL``, ``L_FCC`` ...).

    Parameters
    ----------
    names : sequence of str
        Marker names (model names, or lab labels with the subject prefix stripped).

    Returns
    -------
    dict of str to str or None
        The left and the right heel marker; None when a side has none or more than one.
    """
    found: dict[str, list[str]] = {"l": [], "r": []}
    for name in names:
        for side, landmark in _landmarks(str(name)):
            if landmark == "heel" and side in found:
                found[side].append(str(name))
    if len(found["l"]) != 1 or len(found["r"]) != 1:
        return None
    return {"left": found["l"][0], "right": found["r"][0]}
