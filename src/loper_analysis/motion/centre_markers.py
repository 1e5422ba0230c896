"""The subject calibration's virtual markers on a marker-set template's model.

A template with ``joint_centres`` (:class:`JointCentreSpec`) calibrates a subject through joint centres
(:mod:`loper_analysis.motion.joint_centres` computes them in the static trial): virtual markers at the model's hip,
knee and ankle centres (the child body's origin in the parent body's frame, in the model's default pose), one
forward of the pelvis along the template's spines and one above each ankle (:func:`joint_centre_places`). This
module tells which of them a static trial yields (:func:`calibration_centres`), where they sit on the model, and
which template a model's marker set belongs to (:func:`marker_set_centres`), for the scaling step.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from loper_analysis.constants import SIDE_SUFFIX, SIDES
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.joint_centres import DIRECTION_LEVER_M, PELVIS_DIRECTION, Landmarks

__all__ = [
    "JointCentreSpec",
    "calibration_centres",
    "centre_names",
    "joint_centre_places",
    "joint_centre_spec",
    "marker_set_centres",
]


@dataclass(frozen=True)
class JointCentreSpec:
    """A template's joint centres: virtual markers at the model's joint centres, matched to the centres the static
    trial's markers give (:func:`loper_analysis.motion.joint_centres.static_joint_centres`).

    Attributes
    ----------
    centres : dict
        Virtual marker (``LHJC``, ...) -> (parent body, child body): the centre is the child's origin in the
        parent's frame, in the model's default pose.
    landmarks : Landmarks
        The template's codes of the markers the static trial's centres are computed from.
    weight : float
        The centres' weight when the static pose is fitted.
    foot_bodies : dict
        Side -> the foot's body (its direction marker's).
    others_weight : float
        Every other marker's weight in that fit: they only settle the turns the centres leave free (the femur's
        about its axis when the knee is straight), and pull the pose no further.
    """

    centres: dict[str, tuple[str, str]]
    landmarks: Landmarks
    weight: float
    foot_bodies: dict[str, str]
    others_weight: float = 0.1

    @property
    def names(self) -> list[str]:
        """The virtual markers: the centres, the pelvis's and each foot's direction markers."""
        lm = self.landmarks
        return [
            *self.centres,
            *PELVIS_DIRECTION,
            *(name for side in SIDES for name in (*lm.knee_axis(side), *lm.foot_direction(side))),
        ]


def joint_centre_spec(spec, prefix: Mapping[str, str]) -> JointCentreSpec | None:
    """A template's ``joint_centres`` entry (None without one), the side ``prefix`` (side -> ``L``/``R``) applied."""
    if not spec:
        return None
    centres = {}
    for code, (parent, child) in spec["centres"].items():
        for side in SIDES:
            s = SIDE_SUFFIX[side]
            centres[f"{prefix[side]}{code}"] = (str(parent).format(s=s), str(child).format(s=s))
    landmarks = Landmarks(**{str(k): str(v or "") for k, v in spec["landmarks"].items()}, prefix=dict(prefix))
    feet = {side: str(spec["foot_body"]).format(s=SIDE_SUFFIX[side]) for side in SIDES}
    return JointCentreSpec(centres, landmarks, float(spec["weight"]), feet, float(spec["others_weight"]))


def marker_set_centres(specs: Sequence[JointCentreSpec | None], marker_names: Sequence[str]) -> JointCentreSpec | None:
    """Of the templates' joint centres (``specs``, None for a template without), those whose virtual markers a
    model's marker set holds (None: the marker set holds no template's centres: a lab's own marker set, or one
    written before the calibration through joint centres)."""
    have = set(marker_names)
    for spec in specs:
        names = centre_names(spec)
        if names and all(n in have for n in names):
            return spec
    return None


def centre_names(spec: JointCentreSpec | None) -> list[str]:
    """A template's virtual markers of its joint centres ``spec`` (none without joint centres)."""
    return [] if spec is None else spec.names


def joint_centre_places(
    spec: JointCentreSpec | None,
    landmarks: Mapping[str, tuple[str, tuple[float, float, float]]],
    model,
    source: str,
) -> dict[str, tuple[str, tuple[float, float, float]]]:
    """Each virtual marker of the calibration ``spec`` -> (body, location in its frame, m) on ``model``, in the model's
    default pose: a joint centre is the child body's origin in the parent body's frame; the pelvis's direction
    markers lie :data:`~loper_analysis.motion.joint_centres.DIRECTION_LEVER_M` ahead of and behind the hips' midpoint
    along the line from the template's posterior spines (or sacrum) to its anterior spines, a foot's above and below
    the ankle centre (against the model's gravity: the foot stands flat in the default pose). Empty for a template
    without joint centres. ``landmarks``: the template's markers, name -> (body, location in its frame, m);
    ``source``: the template, as the messages name it.

    Raises
    ------
    LoperInputError
        A body or landmark the template names that the model or template lacks (naming ``source``).
    """
    if spec is None:
        return {}
    import numpy as np

    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    model = model.clone()
    state = model.initSystem()
    bodies = model.getBodySet()
    ground = model.getGround()

    def body(name: str, what: str):
        if not bodies.contains(name):
            raise LoperInputError(f"{source}: {what} on body {name}, which its model lacks")
        return bodies.get(name)

    def in_ground(name: str, location) -> np.ndarray:
        p = body(name, "a landmark").findStationLocationInGround(state, osim.Vec3(*location))
        return np.array([p[0], p[1], p[2]])

    def in_body(name: str, point: np.ndarray) -> tuple[float, float, float]:
        p = ground.findStationLocationInAnotherFrame(state, osim.Vec3(*map(float, point)), body(name, "a marker"))
        return (float(p[0]), float(p[1]), float(p[2]))

    def landmark(name: str) -> np.ndarray:
        if name not in landmarks:
            raise LoperInputError(f"{source}: the calibration's landmark {name} is not its marker")
        body_name, location = landmarks[name]
        return in_ground(body_name, location)

    out, centre_ground = {}, {}
    for name, (parent, child) in spec.centres.items():
        centre_ground[name] = in_ground(body(child, f"joint centre {name}").getName(), (0.0, 0.0, 0.0))
        out[name] = (parent, in_body(body(parent, f"joint centre {name}").getName(), centre_ground[name]))
    lm = spec.landmarks
    front = 0.5 * (landmark(lm.name("left", lm.asis)) + landmark(lm.name("right", lm.asis)))
    if lm.psis:
        back = 0.5 * (landmark(lm.name("left", lm.psis)) + landmark(lm.name("right", lm.psis)))
    else:
        back = landmark(lm.sacrum)
    hips = 0.5 * (centre_ground[lm.centre("left", "HJC")] + centre_ground[lm.centre("right", "HJC")])
    pelvis = spec.centres[lm.centre("left", "HJC")][0]
    unit = (front - back) / np.linalg.norm(front - back)
    for name, sign in zip(PELVIS_DIRECTION, (1.0, -1.0)):
        out[name] = (pelvis, in_body(pelvis, hips + sign * DIRECTION_LEVER_M * unit))
    for side, lateral in (("left", -1.0), ("right", 1.0)):  # the knee's axis: gait2392's knee turns about z
        knee = centre_ground[lm.centre(side, "KJC")]
        femur = spec.centres[lm.centre(side, "KJC")][0]
        for name, sign in zip(lm.knee_axis(side), (1.0, -1.0)):
            out[name] = (femur, in_body(femur, knee + sign * lateral * DIRECTION_LEVER_M * np.array([0.0, 0.0, 1.0])))
    up = -model.getGravity().to_numpy()
    for side in SIDES:
        ankle = centre_ground[lm.centre(side, "AJC")]
        foot = spec.foot_bodies[side]
        for name, sign in zip(lm.foot_direction(side), (1.0, -1.0)):
            out[name] = (foot, in_body(foot, ankle + sign * DIRECTION_LEVER_M * up / np.linalg.norm(up)))
    return out


def calibration_centres(spec: JointCentreSpec | None, static_markers: Sequence[str] | None) -> list[str]:
    """The joint centres' virtual markers (of a template's ``spec``) a static trial holding ``static_markers``
    (model names, derived ones included) yields: all of them when it holds both anterior spines, the posterior
    spines or the sacrum, the lateral knee and ankle markers, the heel and toe markers, else none (the calibration
    then keeps the template's places)."""
    if spec is None or static_markers is None:
        return []
    lm, have = spec.landmarks, set(static_markers)
    codes = (lm.asis, lm.knee_lateral, lm.ankle_lateral, lm.heel, lm.toe)
    need = [lm.name(side, code) for side in SIDES for code in codes]
    posterior = all(lm.name(side, lm.psis) in have for side in SIDES) or lm.sacrum in have
    return spec.names if posterior and all(n in have for n in need) else []
