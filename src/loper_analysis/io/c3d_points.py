"""Which points of a C3D file are markers.

A C3D file stores every 3-D signal as a *point*. Besides the markers a lab
placed on the subject, Vicon Nexus stores the outputs of its models there:
Plug-in Gait's joint angles (``LHipAngles``, in degrees, x = flexion), joint
forces, moments and powers, scalars, modelled markers (the centre of mass),
and the origin and axis points of its segments (``PELO``, ``LFEA``, ...,
``PEL_MO``, ...). A clinical file can hold 180 points of which 25 are
markers. Read as markers, they would be gap-filled, filtered, written to the
TRC and would move the travel speed and the lab's vertical that the markers
give.

A point is *not* a marker when

* it is listed in one of the ``POINT`` parameters that name non-marker
  points: ``ANGLES``, ``FORCES``, ``MOMENTS``, ``POWERS``, ``SCALARS``,
  ``REACTIONS``, ``MODELED_MARKERS``, and every group parameter that
  ``POINT:TYPE_GROUPS`` names (its even entries: ``ANGLES``, ``FORCES``, ...);
* its name is that of a Plug-in Gait segment point: a segment code
  (``PEL``, ``HED``, ``TRX``, or ``L``/``R`` with ``FE``, ``TI``, ``FO``,
  ``TO``, ``CL``, ``HU``, ``RA``, ``HN``), optionally ``_M``, then ``O``,
  ``A``, ``L`` or ``P`` (origin, anterior, lateral, proximal axis points),
  since Nexus does not always list these in a group;
* it is unlabelled: ``*52`` (Nexus) or ``Unlabeled 12`` (QTM).

Labels are compared without a subject prefix (``Subject:LHipAngles``).
Everything else is a marker, joint centres a lab exports as points
(``RHJC``) included: some labs track them.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from loper_analysis.io.c3d_parameters import param_strings

__all__ = [
    "MARKER",
    "NON_MARKER_GROUPS",
    "SEGMENT_POINT",
    "UNLABELLED",
    "point_kinds",
    "point_units",
]

#: Kind of a point that is a marker.
MARKER = "marker"
#: Kind of a Plug-in Gait segment origin or axis point.
SEGMENT_POINT = "SEGMENT"
#: Kind of an unlabelled point.
UNLABELLED = "UNLABELLED"
#: ``POINT`` parameters that list points of another type than markers, with the parameter holding their unit.
NON_MARKER_GROUPS: dict[str, str] = {
    "ANGLES": "ANGLE_UNITS",
    "FORCES": "FORCE_UNITS",
    "MOMENTS": "MOMENT_UNITS",
    "POWERS": "POWER_UNITS",
    "SCALARS": "SCALAR_UNITS",
    "REACTIONS": "REACTION_UNITS",
    "MODELED_MARKERS": "MODELED_MARKER_UNITS",
}

_SEGMENT = re.compile(r"^(PEL|HED|TRX|[LR](FE|TI|FO|TO|CL|HU|RA|HN))(_M)?[OALP]$")
_UNLABELLED = re.compile(r"^(\*\d+|unlabell?ed(\s*\d+)?)$", re.IGNORECASE)


def _bare(label: str) -> str:
    return str(label).rpartition(":")[2].strip()


def _groups(params) -> list[str]:
    """The ``POINT`` parameters that list non-marker points: the standard ones and those of ``TYPE_GROUPS``."""
    named = param_strings(params, "POINT", "TYPE_GROUPS")[0::2]
    return list(dict.fromkeys([*NON_MARKER_GROUPS, *(g.upper() for g in named if g)]))


def point_kinds(params, labels: Sequence[str]) -> list[str]:
    """The kind of each point: :data:`MARKER`, the ``POINT`` group listing it (``ANGLES``, ...),
    :data:`SEGMENT_POINT` or :data:`UNLABELLED`.

    Parameters
    ----------
    params : dict
        ezc3d's parameter dict of the file.
    labels : sequence of str
        The point labels, in file order (``POINT:LABELS``, ``LABELS2``, ...).

    Returns
    -------
    list of str
        One kind per label; a label listed in two groups takes the first of
        :data:`NON_MARKER_GROUPS`, then ``TYPE_GROUPS`` order.
    """
    listed: dict[str, str] = {}
    for group in _groups(params):
        for label in param_strings(params, "POINT", group):
            listed.setdefault(_bare(label), group)
    kinds = []
    for label in labels:
        bare = _bare(label)
        if bare in listed:
            kinds.append(listed[bare])
        elif _SEGMENT.match(bare):
            kinds.append(SEGMENT_POINT)
        elif _UNLABELLED.match(bare) or not bare:
            kinds.append(UNLABELLED)
        else:
            kinds.append(MARKER)
    return kinds


def point_units(params) -> dict[str, str]:
    """The unit of each non-marker group that declares one (``{"ANGLES": "deg", ...}``)."""
    out = {}
    for group in _groups(params):
        units = param_strings(params, "POINT", NON_MARKER_GROUPS.get(group, f"{group.rstrip('S')}_UNITS"))
        if units and units[0]:
            out[group] = units[0]
    return out
