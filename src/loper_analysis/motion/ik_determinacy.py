"""Which coordinates of an OpenSim model a set of IK markers can determine, from the model's tree.

A coordinate of a joint moves the joint's child body and every body further
from the ground. In IK it is therefore determined in a frame only if

* a weighted marker present (finite) in that frame sits on one of those bodies, or
* a coordinate task of positive weight holds it, or
* the model fixes it: the coordinate is locked, or it is the dependent
  coordinate of an enforced ``CoordinateCouplerConstraint``.

Otherwise OpenSim's solver leaves it where it was (its default value in the
first frame, the previous frame's value later): a number no data support.
:func:`undetermined_coordinates` finds those coordinates frame by frame; IK
writes them as NaN (:func:`loper_analysis.motion.ik.inverse_kinematics`).

:func:`require_markers_beyond_root` refuses a marker set that lies entirely
on the body jointed to the ground (the pelvis): such a set determines no
joint angle, and OpenSim 4.6's ``InverseKinematicsSolver`` crashes the
process (segmentation fault) on it with the generated model
(:func:`loper_analysis.motion.model.build_lower_body_model`, planar pelvis joint).

Models are ``opensim.Model`` objects; markers are arrays (n_frames,
n_markers, 3) in m, NaN where missing.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from loper_analysis.checks import where
from loper_analysis.errors import LoperInputError

__all__ = ["ModelTree", "model_tree", "undetermined_coordinates", "require_markers_beyond_root"]

_GROUND = "ground"


@dataclass(frozen=True)
class ModelTree:
    """The parts of a model's structure that decide which coordinates markers can determine.

    Attributes
    ----------
    coordinates : tuple of str
        Coordinate names in the order of the model's coordinate set.
    moved_bodies : dict of str to frozenset of str
        Coordinate -> the bodies its joint moves (the child body and all bodies downstream).
    marker_bodies : dict of str to str
        Marker -> the body it is attached to.
    root_bodies : frozenset of str
        Bodies jointed directly to the ground.
    fixed : frozenset of str
        Coordinates the model itself fixes (locked, or dependent in an enforced coupler constraint).
    """

    coordinates: tuple[str, ...]
    moved_bodies: dict[str, frozenset[str]]
    marker_bodies: dict[str, str]
    root_bodies: frozenset[str]
    fixed: frozenset[str]


def model_tree(model) -> ModelTree:
    """The :class:`ModelTree` of an ``opensim.Model`` (its connections are finalised here)."""
    import opensim

    model.finalizeConnections()
    children: dict[str, list[str]] = {}
    joint_child: dict[str, str] = {}
    roots = set()
    joints = model.getJointSet()
    for i in range(joints.getSize()):
        joint = joints.get(i)
        parent = joint.getParentFrame().findBaseFrame().getName()
        child = joint.getChildFrame().findBaseFrame().getName()
        children.setdefault(parent, []).append(child)
        joint_child[joint.getName()] = child
        if parent == _GROUND:
            roots.add(child)

    def downstream(body: str) -> frozenset[str]:
        out, todo = set(), [body]
        while todo:
            b = todo.pop()
            if b not in out:
                out.add(b)
                todo.extend(children.get(b, []))
        return frozenset(out)

    cs = model.getCoordinateSet()
    names = tuple(cs.get(i).getName() for i in range(cs.getSize()))
    moved = {c: downstream(joint_child[cs.get(c).getJoint().getName()]) for c in names}
    fixed = {c for c in names if cs.get(c).get_locked()}
    constraints = model.getConstraintSet()
    for i in range(constraints.getSize()):
        coupler = opensim.CoordinateCouplerConstraint.safeDownCast(constraints.get(i))
        if coupler is not None and coupler.get_isEnforced():
            fixed.add(coupler.getDependentCoordinateName())
    ms = model.getMarkerSet()
    marker_bodies = {
        ms.get(i).getName(): ms.get(i).getParentFrame().findBaseFrame().getName() for i in range(ms.getSize())
    }
    return ModelTree(names, moved, marker_bodies, frozenset(roots), frozenset(fixed))


def undetermined_coordinates(
    tree: ModelTree,
    markers_m,
    labels: Sequence[str],
    coordinate_tasks: Mapping[str, tuple[float, float | None]] | None = None,
) -> np.ndarray:
    """Frames in which each coordinate is determined by no marker, task or model constraint.

    Parameters
    ----------
    tree : ModelTree
        The model's structure (:func:`model_tree`).
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres, NaN where missing: the
        weighted markers of the IK problem only.
    labels : sequence of str
        One model marker name per marker.
    coordinate_tasks : mapping, optional
        {coordinate: (weight, value or None)}; a task of positive weight determines its coordinate.

    Returns
    -------
    numpy.ndarray of bool
        Shape (n_frames, n_coordinates), coordinates in ``tree.coordinates``
        order; True where the coordinate is undetermined in that frame.
    """
    X = np.asarray(markers_m, dtype=float)
    labels = list(labels)
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[1] != len(labels):
        raise LoperInputError(f"markers_m must have shape (n_frames, {len(labels)}, 3), got {X.shape}")
    present = np.all(np.isfinite(X), axis=2)  # (n_frames, n_markers)
    tasks = {c for c, (w, _) in (coordinate_tasks or {}).items() if float(w) > 0}
    body_of = [tree.marker_bodies.get(lab) for lab in labels]
    out = np.zeros((X.shape[0], len(tree.coordinates)), dtype=bool)
    for j, c in enumerate(tree.coordinates):
        if c in tree.fixed or c in tasks:
            continue
        on = [k for k, b in enumerate(body_of) if b in tree.moved_bodies[c]]
        out[:, j] = ~present[:, on].any(axis=1) if on else True
    return out


def require_markers_beyond_root(tree: ModelTree, markers_m, labels: Sequence[str], source: str = "") -> None:
    """Refuse weighted IK markers that all sit on bodies jointed directly to the ground.

    Markers count if present (finite) in at least one frame. Such a set
    fixes the pelvis and no joint angle, and OpenSim 4.6's IK solver crashes
    the process on it for a model with a planar pelvis joint, so it is
    refused before the solver is built.

    Raises
    ------
    LoperInputError
        Naming ``source``, the markers and their body.
    """
    X = np.asarray(markers_m, dtype=float)
    used = [lab for k, lab in enumerate(labels) if np.all(np.isfinite(X[:, k]), axis=1).any()]
    bodies = sorted({tree.marker_bodies.get(lab, "?") for lab in used})
    if used and set(bodies) <= tree.root_bodies:
        raise LoperInputError(
            f"{where(source)}the {len(used)} weighted marker(s) present ({', '.join(used)}) all sit on "
            f"{', '.join(bodies)}, the body jointed to the ground: they determine no joint angle; IK needs "
            "markers on the limbs too"
        )
