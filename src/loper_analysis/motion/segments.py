"""The swing-leg segment table from any scaled OpenSim model (gait2392, Rajagopal2016, our generated model).

The table (:class:`loper_analysis.swing_leg.dynamics.SegmentParameters`) describes
three planar segments. Each is one or more bodies of the OpenSim model,
named by a mapping ``segment_bodies`` (segment -> body names, ``{s}`` for
the side suffix ``r``/``l``):

* thigh = femur; shank = tibia (+ patella where the model has one);
  foot = talus + calcaneus + toes, combined rigidly in the model's default
  pose (:data:`DEFAULT_SEGMENT_BODIES`, right for gait2392 and
  Rajagopal2016). A name ending in ``?`` is optional: it is used when the
  model has it and skipped otherwise (``patella_{s}?``).
* The first body of each segment is its reference body; its proximal joint
  (the joint whose child is that body) is the segment's proximal joint.

Segment frames (``docs/segment_table.md``), all evaluated in the model's
default pose (``model.initSystem()``, every coordinate at its default
value, which is zero for the knee, ankle, subtalar and mtp joints of both
models distributed with OpenSim):

* thigh: origin at the hip centre, fixed to the femur: the femur frame
  turned about its z axis so that the knee centre lies on -y;
* shank: origin at the knee centre, fixed to the tibia: the tibia frame
  turned about its z axis so that the ankle centre lies on -y;
* foot: origin at the ankle centre, axes those of the shank frame (the
  foot's neutral pose is the one at ankle angle zero, where our ankle angle
  is zero too).

A joint centre is the origin of the joint's child frame. Lengths are the
sagittal (x, y) distance hip -> knee, knee -> ankle in the segment frame,
and for the foot ankle -> the proximal joint centre of the foot's last
body (the mtp joint, the toes' origin): a joint centre the scaled model
defines, unlike the toe tip. A one-body foot has no such joint; its length
is then twice the ankle-to-COM distance (the foot's length does not enter
the equations of motion). COM (x, y) and the moment of inertia about z at
the segment COM come from each body's mass, mass centre and inertia tensor
(about its own COM, in its own frame) turned into the segment frame, summed
with the parallel-axis theorem. The cart mass is the model's total mass
minus one leg's three segments. The rod attachment is the projection of
the midpoint of the brace markers on the thigh axis when the model has
both markers, else ``attachment_fraction`` of the thigh length.

The generated model of :mod:`loper_analysis.motion.model` (bodies ``thigh_{s}``,
``shank_{s}``, ``foot_{s}``) keeps its own table
(:func:`loper_analysis.motion.model.segment_parameters_from_model`): with
``segment_bodies=None`` it is recognised by those bodies.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from loper_analysis.checks import number, where
from loper_analysis.constants import SEGMENTS
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.model import BRACE_MARKERS, segment_parameters_from_model
from loper_analysis.swing_leg.dynamics import BRACE_ATTACHMENT_FRACTION

if TYPE_CHECKING:
    from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = [
    "DEFAULT_SEGMENT_BODIES",
    "GENERATED_MODEL_BODIES",
    "SEGMENT_BODIES_SETTING",
    "segment_body_names",
    "check_segment_bodies",
    "segments_from_model",
]

#: The configuration setting that holds the mapping (named in error messages).
SEGMENT_BODIES_SETTING = "model.segment_bodies"
#: gait2392 and Rajagopal2016 (OpenSim's own naming); ``?`` marks a body used only where the model has it.
DEFAULT_SEGMENT_BODIES: dict[str, tuple[str, ...]] = {
    "thigh": ("femur_{s}",),
    "shank": ("tibia_{s}", "patella_{s}?"),
    "foot": ("talus_{s}", "calcn_{s}", "toes_{s}"),
}
#: The generated model of :mod:`loper_analysis.motion.model`.
GENERATED_MODEL_BODIES: dict[str, tuple[str, ...]] = {
    "thigh": ("thigh_{s}",),
    "shank": ("shank_{s}",),
    "foot": ("foot_{s}",),
}


def _model_file(model, source: str) -> str:
    return source or model.getInputFileName() or f"model {model.getName()}"


def _body_names(model) -> list[str]:
    bodies = model.getBodySet()
    return [bodies.get(i).getName() for i in range(bodies.getSize())]


def segment_body_names(
    model, side: str, segment_bodies: Mapping[str, Sequence[str]] | None = None, source: str = ""
) -> dict[str, list[str]]:
    """The bodies of each segment (thigh, shank, foot) of an ``opensim.Model`` for one side (``"l"`` or ``"r"``).

    ``segment_bodies`` maps each segment to body names with ``{s}`` for the
    side suffix; a trailing ``?`` marks an optional body. ``None`` picks
    :data:`GENERATED_MODEL_BODIES` when the model has ``thigh_{s}``, else
    :data:`DEFAULT_SEGMENT_BODIES`. ``source`` names the model file in errors.

    Raises
    ------
    LoperInputError
        A segment missing from the mapping or without bodies, a side other
        than ``l``/``r``, or a required body the model lacks (the message
        names the model file, the setting ``model.segment_bodies`` and the body).
    """
    if side not in ("l", "r"):
        raise LoperInputError(f"side must be 'l' or 'r' (OpenSim suffix), got {side!r}")
    present = _body_names(model)
    if segment_bodies is None:
        segment_bodies = GENERATED_MODEL_BODIES if f"thigh_{side}" in present else DEFAULT_SEGMENT_BODIES
    out: dict[str, list[str]] = {}
    for seg in SEGMENTS:
        names = segment_bodies.get(seg) if isinstance(segment_bodies, Mapping) else None
        if isinstance(names, str):
            names = [names]
        if not names:
            raise LoperInputError(
                f"{SEGMENT_BODIES_SETTING}: segment '{seg}' needs a list of body names, got {names!r}"
            )
        chosen = []
        for raw in names:
            optional = str(raw).endswith("?")
            name = str(raw).rstrip("?").replace("{s}", side)
            if name in present:
                chosen.append(name)
            elif not optional:
                raise LoperInputError(
                    f"{_model_file(model, source)}: {SEGMENT_BODIES_SETTING}: {seg} body '{name}' is not in the model "
                    f"(its bodies: {', '.join(present)})"
                )
        if not chosen:
            raise LoperInputError(
                f"{_model_file(model, source)}: {SEGMENT_BODIES_SETTING}: no body of the {seg} "
                f"({list(names)}) is in the model"
            )
        out[seg] = chosen
    return out


def check_segment_bodies(
    model,
    segment_bodies: Mapping[str, Sequence[str]] | None = None,
    sides: Sequence[str] = ("l", "r"),
    source: str = "",
) -> None:
    """Raise :class:`LoperInputError` unless the model has every configured body on each side (see
    :func:`segment_body_names`)."""
    for side in sides:
        segment_body_names(model, side, segment_bodies, source)


def _transform(frame, state) -> tuple[np.ndarray, np.ndarray]:
    """Rotation (3, 3) and origin (3,) in ground of an OpenSim frame."""
    T = frame.getTransformInGround(state)
    M = T.R().asMat33()
    return np.array([[M.get(i, j) for j in range(3)] for i in range(3)]), T.p().to_numpy().copy()


def _proximal_joint_centre(model, state, body: str, source: str) -> np.ndarray:
    """Ground position (3,) of the child-frame origin of the joint whose child is ``body``."""
    joints = model.getJointSet()
    for i in range(joints.getSize()):
        frame = joints.get(i).getChildFrame()
        if frame.findBaseFrame().getName() == body:
            return frame.getPositionInGround(state).to_numpy().copy()
    raise LoperInputError(f"{_model_file(model, source)}: body '{body}' is the child of no joint")


def _sagittal_turn(v: np.ndarray) -> np.ndarray:
    """Rotation (3, 3) about z taking the sagittal part of ``v`` onto -y (|v_xy| along -y)."""
    L = float(np.hypot(v[0], v[1]))
    if L <= 0:
        raise LoperInputError("a segment's distal joint coincides with its proximal joint")
    c, s = -v[1] / L, v[0] / L
    return np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])


def _inertia(body) -> np.ndarray:
    """Inertia tensor (3, 3) about the body's COM in the body frame, kg m^2."""
    inertia = body.getInertia()
    (xx, yy, zz), (xy, xz, yz) = inertia.getMoments().to_numpy(), inertia.getProducts().to_numpy()
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])


def _combined(
    model, state, names: list[str], origin: np.ndarray, to_segment: np.ndarray
) -> tuple[float, np.ndarray, float]:
    """Mass (kg), COM (x, y) (m) and inertia about z at the COM (kg m^2) of rigidly joined bodies in a segment frame.

    ``to_segment`` (3, 3) turns ground vectors into the segment frame, whose
    origin is ``origin`` (ground, m).
    """
    bodies = model.getBodySet()
    masses, coms, izz = [], [], []
    for name in names:
        b = bodies.get(name)
        R, p = _transform(b, state)
        Q = to_segment @ R  # body frame -> segment frame
        masses.append(b.getMass())
        coms.append(to_segment @ (p + R @ b.getMassCenter().to_numpy() - origin))
        izz.append((Q @ _inertia(b) @ Q.T)[2, 2])
    m = np.asarray(masses)
    r = np.asarray(coms)[:, :2]
    total = float(m.sum())
    if total <= 0:
        raise LoperInputError(f"bodies {names} have no mass")
    c = (m[:, None] * r).sum(axis=0) / total
    inertia = float(np.sum(izz) + np.sum(m * np.sum((r - c) ** 2, axis=1)))
    return total, c, inertia


def segments_from_model(
    model,
    side: str = "l",
    segment_bodies: Mapping[str, Sequence[str]] | None = None,
    attachment_fraction: float = BRACE_ATTACHMENT_FRACTION,
    brace_markers: Sequence[str] = BRACE_MARKERS,
    source: str = "",
) -> SegmentParameters:
    """Swing-leg segment table of one leg of a (scaled) ``opensim.Model``, in the model's default pose.

    Parameters
    ----------
    model : opensim.Model
        Any model whose bodies ``segment_bodies`` names (the module docstring
        gives the frames); its system is initialised here.
    side : {"l", "r"}
        OpenSim side suffix of the swing leg.
    segment_bodies : mapping, optional
        Segment -> body names (see :func:`segment_body_names`); ``None``:
        our generated model when it has ``thigh_{side}`` (its own table,
        :func:`loper_analysis.motion.model.segment_parameters_from_model`), else
        :data:`DEFAULT_SEGMENT_BODIES`.
    attachment_fraction : float
        Rod attachment as a fraction (0 .. 1) of the thigh length from the
        hip, used when the model lacks the brace markers.
    brace_markers : sequence of str
        The two brace markers whose midpoint, projected on the thigh axis,
        gives the attachment.
    source : str
        The model file, for messages (default: the file OpenSim read).

    Returns
    -------
    SegmentParameters
        Masses (kg), inertias about z at the COM (kg m^2), lengths (m), COM
        (x, y) in the segment frames (m), cart mass (kg), attachment (m),
        gravity (m/s^2, the model's).

    Raises
    ------
    LoperInputError
        A configured body missing (naming the file, ``model.segment_bodies``
        and the body), an attachment fraction outside 0 .. 1, or a table the
        dynamics model refuses.
    """
    from loper_analysis.swing_leg.dynamics import SegmentParameters

    fraction = number("attachment_fraction", attachment_fraction, source, 0.0, 1.0)
    state = model.initSystem()
    names = segment_body_names(model, side, segment_bodies, source)
    if segment_bodies is None and names["thigh"] == [f"thigh_{side}"]:
        return segment_parameters_from_model(model, side=side, brace_markers=tuple(brace_markers))
    bodies = model.getBodySet()
    hip, knee, ankle = (_proximal_joint_centre(model, state, names[seg][0], source) for seg in SEGMENTS)
    turns, origins, lengths = {}, {"thigh": hip, "shank": knee, "foot": ankle}, []
    for seg, distal in (("thigh", knee), ("shank", ankle)):
        R, _ = _transform(bodies.get(names[seg][0]), state)
        d = R.T @ (distal - origins[seg])  # distal joint in the reference body's frame
        turns[seg] = _sagittal_turn(d) @ R.T  # ground -> segment frame
        lengths.append(float(np.hypot(d[0], d[1])))
    turns["foot"] = turns["shank"]
    masses, inertias, coms = [], [], []
    for seg in SEGMENTS:
        m, c, inertia = _combined(model, state, names[seg], origins[seg], turns[seg])
        masses.append(m)
        coms.append(c)
        inertias.append(inertia)
    if len(names["foot"]) > 1:
        toe = turns["foot"] @ (_proximal_joint_centre(model, state, names["foot"][-1], source) - ankle)
        lengths.append(float(np.hypot(toe[0], toe[1])))
    else:
        lengths.append(2.0 * float(np.hypot(*coms[2])))
    total = sum(bodies.get(i).getMass() for i in range(bodies.getSize()))
    attachment = _attachment(model, state, brace_markers, hip, turns["thigh"])
    if attachment is None:
        attachment = fraction * lengths[0]
    try:
        return SegmentParameters(
            cart_mass_kg=total - sum(masses),
            mass_kg=tuple(masses),
            inertia_kg_m2=tuple(inertias),
            length_m=tuple(lengths),
            com_x_m=tuple(c[0] for c in coms),
            com_y_m=tuple(c[1] for c in coms),
            attachment_m=attachment,
            gravity_m_per_s2=float(-model.getGravity().get(1)),
        )
    except LoperInputError as exc:
        raise LoperInputError(f"{where(_model_file(model, source))}{exc}") from None


def _attachment(model, state, brace_markers: Sequence[str], hip: np.ndarray, to_thigh: np.ndarray) -> float | None:
    """Distance (m) from the hip of the brace markers' midpoint projected on the thigh axis; None without them."""
    markers = model.getMarkerSet()
    present = {markers.get(i).getName() for i in range(markers.getSize())}
    if len(brace_markers) != 2 or not set(brace_markers) <= present:
        return None
    mid = 0.5 * sum(markers.get(name).getLocationInGround(state).to_numpy() for name in brace_markers)
    return float(-(to_thigh @ (mid - hip))[1])
