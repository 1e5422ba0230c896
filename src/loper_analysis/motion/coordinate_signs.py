"""The sign of a model coordinate in our joint-angle convention, read from the model's own kinematics.

Models disagree on signs: gait2392's knee angle is negative in flexion,
Rajagopal2016's positive, and OpenSim's ``pelvis_tilt`` is positive with the
front of the pelvis up where our pelvis angle is positive in anterior tilt
([conventions](conventions.md)). A coordinate map with the wrong sign gives
a knee that "flexes" to -60 degrees in swing: plausible-looking and wrong.

The sign is measured, not looked up. The model is put in its default pose,
the coordinate is moved by a small step, and the rotation of the joint's
child body relative to its parent is read about the model's lateral axis
(+Z, OpenSim's right; +Y up, +X forward). With the right-hand rule a
positive rotation about +Z turns the forward axis up and a hanging segment
forward. Therefore

* hip flexion (the thigh's distal end forward) is a positive rotation of the
  thigh relative to the pelvis;
* knee flexion (the shank's distal end backward) is a negative rotation of
  the shank relative to the thigh;
* ankle dorsiflexion (the toes up) is a positive rotation of the foot
  relative to the shank;
* anterior pelvic tilt (the front down) is a negative rotation of the pelvis
  relative to the ground;
* the pelvis translation is positive when the pelvis moves forward (+X).

A coordinate that turns its body mostly about another axis (or moves it
mostly along another axis) has no sagittal sign: None.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["ANATOMICAL_SENSE", "coordinate_sign", "map_signs", "require_map_signs"]

#: Per angle of the coordinate map, the sign of a positive angle as a rotation about the model's lateral +Z
#: (rotations) or a displacement along its forward +X (``pelvis_x``).
ANATOMICAL_SENSE: dict[str, float] = {
    "pelvis_x": 1.0,
    "pelvis_angle": -1.0,
    "hip_left": 1.0,
    "hip_right": 1.0,
    "knee_left": -1.0,
    "knee_right": -1.0,
    "ankle_left": 1.0,
    "ankle_right": 1.0,
}
#: Step of the coordinate (rad or m) whose effect is read.
_STEP = 0.05
#: Least share of the motion that must lie about +Z (or along +X) for a sign to be read.
_MIN_SAGITTAL_SHARE = 0.7


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    """Rotation vector (axis * angle, rad) of a 3x3 rotation matrix (small angles)."""
    angle = np.arccos(np.clip((np.trace(R) - 1.0) / 2.0, -1.0, 1.0))
    axis = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    norm = np.linalg.norm(axis)
    return np.zeros(3) if norm == 0 else axis / norm * angle


def _owner(model, coordinate: str):
    """The joint owning a coordinate (None when the model has no such coordinate)."""
    cs = model.getCoordinateSet()
    if not cs.contains(coordinate):
        return None
    return cs.get(coordinate).getJoint()


def coordinate_sign(model, coordinate: str, translation: bool = False, state=None) -> float | None:
    """How a coordinate moves its joint's child body: the sign of its rotation about the model's +Z
    relative to the parent (or, ``translation``, of its displacement along +X), from the default pose.

    Parameters
    ----------
    model : opensim.Model
        The model (its default pose is used; the model is not changed).
    coordinate : str
        A coordinate of the model.
    translation : bool
        Read the displacement along +X instead of the rotation about +Z.
    state : opensim.State, optional
        The model's initialised state (``model.initSystem()``), to spare another initialisation.

    Returns
    -------
    float or None
        +1.0 or -1.0; None when the model has no such coordinate or the motion lies mostly about
        (along) another axis.
    """
    joint = _owner(model, coordinate)
    if joint is None:
        return None
    state = model.initSystem() if state is None else state
    coord = model.getCoordinateSet().get(coordinate)
    child = joint.getChildFrame()

    def pose(value: float) -> tuple[np.ndarray, np.ndarray]:
        """The child frame's orientation (3x3) and origin (3,) in ground with the coordinate at ``value``."""
        probe = state.__class__(state)
        if coord.getLocked(probe):
            coord.setLocked(probe, False)
        coord.setValue(probe, value, False)
        model.realizePosition(probe)
        R = child.getTransformInGround(probe).R().asMat33()
        return np.array([[R.get(i, j) for j in range(3)] for i in range(3)]), child.getPositionInGround(
            probe
        ).to_numpy()

    value = coord.getDefaultValue()
    (R0, x0), (R1, x1) = pose(value), pose(value + _STEP)
    if translation:
        motion = x1 - x0
    else:
        motion = _rotation_vector(R1 @ R0.T)  # the step's rotation in ground (the parent does not move)
    component = motion[0] if translation else motion[2]
    size = np.linalg.norm(motion)
    if size == 0 or abs(component) < _MIN_SAGITTAL_SHARE * size:
        return None
    return float(np.sign(component))


def map_signs(model, coordinate_map: Mapping[str, object]) -> dict[str, float | None]:
    """The sign each entry of a coordinate map needs for our convention, from the model's kinematics.

    Parameters
    ----------
    model : opensim.Model
    coordinate_map : mapping
        Angle -> ``{"coordinate": name, "sign": ±1}`` or ``(name, sign)``.

    Returns
    -------
    dict
        Angle -> +1.0 or -1.0, or None where the model does not tell (no such coordinate, or not a sagittal
        motion).
    """
    out: dict[str, float | None] = {}
    state = model.initSystem()
    for key, entry in coordinate_map.items():
        name = entry["coordinate"] if isinstance(entry, Mapping) else entry[0]
        sense = ANATOMICAL_SENSE.get(key)
        moved = None if sense is None else coordinate_sign(model, name, key == "pelvis_x", state)
        out[key] = None if moved is None else float(sense * moved)
    return out


def require_map_signs(model, coordinate_map: Mapping[str, object], source: str, setting: str) -> None:
    """Refuse a coordinate map whose sign contradicts the model's kinematics.

    Raises
    ------
    LoperInputError
        Naming ``source`` (the model), each wrong entry, its coordinate, the
        sign given and the sign the model needs, and ``setting`` (the config
        key of the map).
    """
    needed = map_signs(model, coordinate_map)
    wrong, fixes = [], []
    for key, entry in coordinate_map.items():
        name, sign = (entry["coordinate"], entry["sign"]) if isinstance(entry, Mapping) else entry
        want = needed.get(key)
        if want is not None and float(sign) != want:
            wrong.append(f"{key} ({name}, sign {float(sign):g})")
            fixes.append(f"{setting}.{key}.sign: {want:g}")
    if wrong:
        raise LoperInputError(
            f"{source}: the coordinate map's sign contradicts the model's kinematics for {', '.join(wrong)}: "
            "flexion, dorsiflexion or anterior tilt would come out negative (the model moves the segment the "
            f"other way as the coordinate grows); set {'; '.join(fixes)}"
        )
