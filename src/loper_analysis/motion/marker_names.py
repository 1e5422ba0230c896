"""Marker names: from a lab's C3D labels to the model's marker names.

Labs name their markers in their own way: Vicon Nexus prefixes every label
with the subject (``Subject:LASI``), and marker sets differ in spelling
(``L_ASIS`` for ``LASI``). :func:`model_marker_names` strips the subject
prefix (everything up to the last ``:``) and then renames labels through the
``markers.label_map`` configuration ({lab label: model marker}); labels the
map does not name keep their stripped name. :func:`require_model_markers`
refuses a trial in which no label provides a model marker the analysis needs.
:func:`with_lab_label` names a model marker with the lab label that provides it, in messages.

Labels with inner spaces (BTS exports ``r heel``) are read, renamed and
written to the TRC as they are; a map key may hold them (``r heel: RHEE``).
A map value is a model marker's name and cannot hold whitespace: OpenSim
refuses whitespace (and ``/ \\ * +``) in the name of any model component, a
marker included, so a label with a space can only reach IK through the map.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

from loper_analysis.errors import LoperInputError

__all__ = [
    "LABEL_MAP_FIELD",
    "missing_model_markers",
    "model_marker_names",
    "require_model_markers",
    "strip_subject_prefix",
    "unknown_markers_hint",
    "with_lab_label",
]

#: Configuration field of the label map (named in messages).
LABEL_MAP_FIELD = "markers.label_map"

_MAX_LISTED = 12


def strip_subject_prefix(label: str) -> str:
    """The label without a subject prefix: everything up to the last ``:`` removed (``Subject:LASI`` -> ``LASI``)."""
    return str(label).rpartition(":")[2].strip()


def _listed(names: Sequence[str]) -> str:
    more = len(names) - _MAX_LISTED
    return ", ".join(names[:_MAX_LISTED]) + (f", ... ({more} more)" if more > 0 else "")


def model_marker_names(
    labels: Sequence[str], label_map: Mapping[str, str] | None = None, source: str = ""
) -> list[str]:
    """Model-marker names of a file's labels: subject prefix stripped, then renamed by ``label_map``.

    Parameters
    ----------
    labels : sequence of str
        The file's marker labels, in file order.
    label_map : mapping of str to str, optional
        {lab label: model marker}. A key matches a file label with or
        without its subject prefix (``LASIS`` matches ``Subject:LASIS``) and
        may hold inner spaces (``r heel``); a value is a model marker name,
        without whitespace (OpenSim's rule for component names). Labels not
        named keep their stripped name (inner spaces included).
    source : str
        The file (for messages).

    Returns
    -------
    list of str
        One name per label, in file order.

    Raises
    ------
    LoperInputError
        A map entry whose label the file lacks, a map value that is not a
        non-empty name without whitespace, or two labels ending up with one
        name. The message names the file, ``markers.label_map`` and the value.
    """
    where = source or "markers"
    raw = [str(lab).strip() for lab in labels]
    names = [strip_subject_prefix(lab) for lab in raw]
    if label_map:
        for key, value in label_map.items():
            if not isinstance(value, str) or not value.strip() or any(c.isspace() for c in value.strip()):
                raise LoperInputError(
                    f"{where}: {LABEL_MAP_FIELD}: '{key}' maps to {value!r}, not a marker name (non-empty, no spaces: "
                    "OpenSim refuses whitespace in a model marker's name)"
                )
        # a key naming the full label (with prefix) wins over one naming the stripped label
        by_key: dict[str, int] = {}
        for i, short in enumerate(names):
            by_key.setdefault(short, i)
        for i, full in enumerate(raw):
            by_key[full] = i
        absent = [str(k) for k in label_map if str(k).strip() not in by_key]
        if absent:
            raise LoperInputError(
                f"{where}: {LABEL_MAP_FIELD}: label(s) {_listed(absent)} not in the file; its labels: {_listed(names)}"
            )
        renamed = list(names)
        for key, value in label_map.items():
            renamed[by_key[str(key).strip()]] = value.strip()
        names = renamed
    seen: dict[str, list[str]] = {}
    for full, name in zip(raw, names):
        seen.setdefault(name, []).append(full)
    twice = {name: fulls for name, fulls in seen.items() if len(fulls) > 1}
    if twice:
        detail = "; ".join(f"{name} from {', '.join(fulls)}" for name, fulls in list(twice.items())[:_MAX_LISTED])
        raise LoperInputError(
            f"{where}: marker names must be unique after removing subject prefixes and applying "
            f"{LABEL_MAP_FIELD}: {detail}"
        )
    return names


def missing_model_markers(names: Sequence[str], required: Sequence[str]) -> list[str]:
    """The model markers of ``required`` (in their order) that no name in ``names`` provides."""
    have = set(names)
    return [m for m in required if m not in have]


def require_model_markers(
    names: Sequence[str], required: Sequence[str], source: str = "", labels: Sequence[str] | None = None
) -> None:
    """Refuse a trial in which no label provides one of the ``required`` model markers.

    ``names`` are the file's model-marker names (:func:`model_marker_names`);
    ``labels`` (the file's own labels) are quoted in the message when given.

    Raises
    ------
    LoperInputError
        Listing every missing model marker, the file and the field to fix
        (``markers.label_map``).
    """
    missing = missing_model_markers(names, required)
    if missing:
        shown = list(labels) if labels is not None else list(names)
        raise LoperInputError(
            f"{source or 'markers'}: model marker(s) {_listed(missing)} not provided by any label of the file "
            f"(map lab labels to them in {LABEL_MAP_FIELD}); the file's labels: {_listed(shown)}"
        )


def unknown_markers_hint(
    labels: Sequence[str], model_markers: Sequence[str], lab_labels: Mapping[str, str] | None
) -> str:
    """The trial's markers the model does not have, as a hint at a label-map typo ('' when there are none)."""
    import difflib

    unknown = [m for m in labels if m not in set(model_markers)]
    if not unknown:
        return ""
    shown = []
    for m in unknown:
        label = (lab_labels or {}).get(m)
        close = difflib.get_close_matches(m, model_markers, n=1)
        shown.append(
            (f"'{label}' mapped to {m}" if label and label != m else f"'{m}'")
            + (f" (the model has {close[0]})" if close else "")
        )
    return (
        f"; the trial's marker(s) {', '.join(shown)} are not on the model: a typo in the label map "
        "(markers.label_map, markers.trial_label_maps)?"
    )


def with_lab_label(marker: str, lab_labels: Mapping[str, str] | None) -> str:
    """A model marker with the lab label that provides it: ``'RKNE' (model marker R.Knee)``."""
    label = (lab_labels or {}).get(marker)
    return f"'{label}' (model marker {marker})" if label and label != marker else f"'{marker}'"
