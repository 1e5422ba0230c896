"""The generic sagittal-plane lower-body OpenSim model and the segment table it yields.

Built with the OpenSim API (no CustomJoint, which crashed when built from
Python in older OpenSim versions):

* ``pelvis`` on a ``PlanarJoint`` (``pelvis_tilt`` about Z, ``pelvis_tx``,
  ``pelvis_ty``); it carries head, arms and trunk (HAT) as one mass.
* per side (suffix ``s`` in {r, l}): ``thigh_s``, ``shank_s``, ``foot_s`` on
  ``PinJoint``s about Z with coordinates ``hip_flexion_s``, ``knee_flexion_s``,
  ``ankle_dorsiflexion_s``, all positive in flexion / dorsiflexion (the knee
  joint frames are turned half a turn about Y so that knee flexion is
  positive, unlike gait2392's ``knee_angle``).
* Axes: X forward, Y up, Z to the right (OpenSim's convention).
* Onto the swing-leg model (:mod:`loper_analysis.swing_leg.dynamics`): cart x =
  ``pelvis_tx``, the pelvis angle there is ``-pelvis_tilt``, and the joint
  angles are the coordinates themselves (checked against OpenSim's body
  positions in ``tests/motion/test_model.py``).

Segment masses, lengths, COM and radii of gyration follow Winter's table
(:mod:`loper_analysis.swing_leg.anthropometry`), as do
:func:`loper_analysis.swing_leg.dynamics.segment_parameters_from_anthropometry`.

The marker set is close to a 32-marker Qualisys lower-body set: pelvis
(RASI, LASI, RPSI, LPSI) and per leg greater trochanter, a 4-marker thigh
cluster, lateral and medial knee, a 3-marker shank cluster, lateral and
medial malleolus, heel, 1st and 5th metatarsal heads; plus two brace markers
on the left thigh (``LBRA_P``, ``LBRA_D``) whose line gives the rod force
direction and whose midpoint the rod attachment.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from loper_analysis.constants import SEGMENTS, SIDE_SUFFIX
from loper_analysis.errors import LoperInputError
from loper_analysis.io.osim import quiet_opensim
from loper_analysis.study_design import PERTURBED_SIDE
from loper_analysis.swing_leg.anthropometry import (
    ANKLE_HEIGHT_FRACTION,
    HAT_COM_FRACTION,
    HAT_GYRATION_FRACTION,
    HEEL_BEHIND_ANKLE_FRACTION,
    HIP_HALF_WIDTH_FRACTION,
    HIP_TO_SHOULDER_FRACTION,
    PELVIS_DEPTH_FRACTION,
    WINTER_SEGMENTS,
)

if TYPE_CHECKING:  # the dynamics (numba kernels) load only when a segment table is made
    from loper_analysis.swing_leg.dynamics import SegmentParameters

__all__ = [
    "MARKERS",
    "BRACE_MARKERS",
    "COORDINATES",
    "SCALE_MEASUREMENTS",
    "model_dimensions",
    "build_lower_body_model",
    "segment_parameters_from_model",
]

#: OpenSim side suffixes in the order the model builds the legs (right leg first).
_LEGS = (SIDE_SUFFIX["right"], SIDE_SUFFIX["left"])
BRACE_MARKERS = ("LBRA_P", "LBRA_D")
COORDINATES = (
    "pelvis_tilt",
    "pelvis_tx",
    "pelvis_ty",
    "hip_flexion_r",
    "knee_flexion_r",
    "ankle_dorsiflexion_r",
    "hip_flexion_l",
    "knee_flexion_l",
    "ankle_dorsiflexion_l",
)


def model_dimensions(height_m: float, mass_kg: float) -> dict:
    """Masses (kg) and lengths (m) of the generic model for a subject (Winter's table).

    ``segments``: per segment ``mass``, ``length`` and the fractions ``com``
    and ``k`` (radius of gyration) of its length; ``pelvis_mass`` (pelvis
    with head, arms and trunk), ``hat_com_height``, ``hat_k``,
    ``hip_half_width``, ``pelvis_depth``, ``ankle_height``.
    """
    H, M = height_m, mass_kg
    seg = {
        s: dict(
            mass=WINTER_SEGMENTS[s].mass * M,
            length=WINTER_SEGMENTS[s].length * H,
            com=WINTER_SEGMENTS[s].com,
            k=WINTER_SEGMENTS[s].gyration,
        )
        for s in SEGMENTS
    }
    leg = sum(s["mass"] for s in seg.values())
    pelvis_hat = M - 2 * leg
    return {
        "segments": seg,
        "pelvis_mass": pelvis_hat,
        "hat_com_height": HAT_COM_FRACTION * HIP_TO_SHOULDER_FRACTION * H,
        "hat_k": HAT_GYRATION_FRACTION * HIP_TO_SHOULDER_FRACTION * H,
        "hip_half_width": HIP_HALF_WIDTH_FRACTION * H,
        "pelvis_depth": PELVIS_DEPTH_FRACTION * H,
        "ankle_height": ANKLE_HEIGHT_FRACTION * H,
    }


def _marker_table(a: dict) -> list[tuple[str, str, tuple[float, float, float]]]:
    """(name, body, location in the body frame, m)."""
    s = a["segments"]
    Lt, Ls, Lf = s["thigh"]["length"], s["shank"]["length"], s["foot"]["length"]
    w, d, ah = a["hip_half_width"], a["pelvis_depth"], a["ankle_height"]
    out = [
        ("RASI", "pelvis", (0.6 * d, 0.09, 0.9 * w)),
        ("LASI", "pelvis", (0.6 * d, 0.09, -0.9 * w)),
        ("RPSI", "pelvis", (-0.4 * d, 0.11, 0.35 * w)),
        ("LPSI", "pelvis", (-0.4 * d, 0.11, -0.35 * w)),
    ]
    for side in _LEGS:
        S = side.upper()
        z = 1.0 if side == "r" else -1.0  # lateral direction of this leg
        out += [
            (f"{S}GTR", f"thigh_{side}", (0.0, -0.02, z * 0.09)),
            (f"{S}THI_AS", f"thigh_{side}", (0.05, -0.35 * Lt, z * 0.07)),
            (f"{S}THI_PS", f"thigh_{side}", (-0.04, -0.38 * Lt, z * 0.07)),
            (f"{S}THI_AI", f"thigh_{side}", (0.05, -0.55 * Lt, z * 0.065)),
            (f"{S}THI_PI", f"thigh_{side}", (-0.04, -0.58 * Lt, z * 0.065)),
            (f"{S}KNE", f"thigh_{side}", (0.0, -Lt, z * 0.05)),
            (f"{S}KNM", f"thigh_{side}", (0.0, -Lt, -z * 0.05)),
            (f"{S}TIB_AS", f"shank_{side}", (0.04, -0.3 * Ls, z * 0.055)),
            (f"{S}TIB_PS", f"shank_{side}", (-0.04, -0.35 * Ls, z * 0.055)),
            (f"{S}TIB_AI", f"shank_{side}", (0.035, -0.6 * Ls, z * 0.045)),
            (f"{S}ANK", f"shank_{side}", (0.0, -Ls, z * 0.035)),
            (f"{S}ANM", f"shank_{side}", (0.0, -Ls, -z * 0.035)),
            (f"{S}HEE", f"foot_{side}", (-HEEL_BEHIND_ANKLE_FRACTION * Lf, -0.6 * ah, 0.0)),
            (f"{S}MT1", f"foot_{side}", (0.75 * Lf, -ah, -z * 0.035)),
            (f"{S}MT5", f"foot_{side}", (0.65 * Lf, -ah, z * 0.035)),
        ]
    out += [
        ("LBRA_P", "thigh_l", (0.07, -0.72 * Lt, -0.06)),
        ("LBRA_D", "thigh_l", (0.07, -0.88 * Lt, -0.06)),
    ]
    return out


#: Marker names of the default model, in model order.
MARKERS: tuple[str, ...] = tuple(name for name, _, _ in _marker_table(model_dimensions(1.75, 70.0)))


def build_lower_body_model(height_m: float, mass_kg: float, name: str = "loper_lower_body"):
    """The generic model for a subject of this height and mass, an ``opensim.Model`` (system initialised)."""
    if not 1.0 <= height_m <= 2.5:
        raise LoperInputError(f"height_m must lie in 1 .. 2.5 m, got {height_m}")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    osim = quiet_opensim()
    a = model_dimensions(float(height_m), float(mass_kg))
    model = osim.Model()
    model.setName(name)
    model.setGravity(osim.Vec3(0, -9.81, 0))
    ground = model.getGround()

    def inertia(m, k_xy, k_z):
        return osim.Inertia(m * k_xy**2, m * k_xy**2, m * k_z**2)

    pelvis = osim.Body(
        "pelvis",
        a["pelvis_mass"],
        osim.Vec3(0, a["hat_com_height"], 0),
        inertia(a["pelvis_mass"], a["hat_k"], a["hat_k"]),
    )
    model.addBody(pelvis)
    pj = osim.PlanarJoint("pelvis_joint", ground, osim.Vec3(0), osim.Vec3(0), pelvis, osim.Vec3(0), osim.Vec3(0))
    for i, cname in enumerate(("pelvis_tilt", "pelvis_tx", "pelvis_ty")):
        pj.upd_coordinates(i).setName(cname)
    model.addJoint(pj)
    leg_height = a["segments"]["thigh"]["length"] + a["segments"]["shank"]["length"] + a["ankle_height"]
    pj.upd_coordinates(2).setDefaultValue(leg_height)

    for side in _LEGS:
        z = 1.0 if side == "r" else -1.0
        parent = pelvis
        parent_offset = osim.Vec3(0, 0, z * a["hip_half_width"])
        for seg, jname, cname, flip in (
            ("thigh", "hip", "hip_flexion", False),
            ("shank", "knee", "knee_flexion", True),
            ("foot", "ankle", "ankle_dorsiflexion", False),
        ):
            p = a["segments"][seg]
            m, L = p["mass"], p["length"]
            if seg == "foot":
                com = osim.Vec3((p["com"] - HEEL_BEHIND_ANKLE_FRACTION) * L, -0.5 * a["ankle_height"], 0)
            else:
                com = osim.Vec3(0, -p["com"] * L, 0)
            k = p["k"] * L
            body = osim.Body(f"{seg}_{side}", m, com, inertia(m, k, k))
            model.addBody(body)
            orient = osim.Vec3(0, np.pi, 0) if flip else osim.Vec3(0)
            joint = osim.PinJoint(f"{jname}_{side}", parent, parent_offset, orient, body, osim.Vec3(0), orient)
            joint.upd_coordinates(0).setName(f"{cname}_{side}")
            model.addJoint(joint)
            parent = body
            parent_offset = osim.Vec3(0, -L, 0)  # the next joint, at the distal end
    for mname, body, loc in _marker_table(a):
        model.addMarker(osim.Marker(mname, model.getBodySet().get(body), osim.Vec3(*loc)))
    model.finalizeConnections()
    model.initSystem()
    return model


def segment_parameters_from_model(
    model, side: str = SIDE_SUFFIX[PERTURBED_SIDE], brace_markers=BRACE_MARKERS
) -> SegmentParameters:
    """Swing-leg segment table from an ``opensim.Model`` built by :func:`build_lower_body_model` (or scaled from it).

    Masses, COM (x, y in the body frame) and the inertia about Z come from the
    bodies ``thigh_{side}``, ``shank_{side}``, ``foot_{side}``; lengths from the
    knee and ankle joint locations; the cart mass is the model mass minus the
    leg; the rod attachment is the projection of the brace markers' midpoint on
    the thigh axis.
    """
    from loper_analysis.swing_leg.dynamics import SegmentParameters

    model.initSystem()
    bodies = model.getBodySet()
    names = [bodies.get(i).getName() for i in range(bodies.getSize())]
    need = [f"{s}_{side}" for s in ("thigh", "shank", "foot")]
    missing = [n for n in need if n not in names]
    if missing:
        raise LoperInputError(f"model {model.getName()}: missing body/bodies {missing}; has {names}")
    total = sum(bodies.get(i).getMass() for i in range(bodies.getSize()))
    masses, inertias, coms_x, coms_y, lengths = [], [], [], [], []
    joints = model.getJointSet()
    for seg in ("thigh", "shank", "foot"):
        b = bodies.get(f"{seg}_{side}")
        masses.append(b.getMass())
        c = b.getMassCenter()
        coms_x.append(c.get(0))
        coms_y.append(c.get(1))
        inertias.append(b.getInertia().getMoments().get(2))
    for jname in (f"knee_{side}", f"ankle_{side}"):
        j = joints.get(jname)
        loc = j.getParentFrame().findTransformInBaseFrame().p()
        lengths.append(float(np.hypot(loc.get(0), loc.get(1))))
    lengths.append(_foot_length(model, side))
    markers = model.getMarkerSet()
    try:
        p = [markers.get(m).get_location() for m in brace_markers]
    except Exception as exc:  # OpenSim raises its own exception type for a missing name
        raise LoperInputError(f"model {model.getName()}: brace markers {brace_markers} not found ({exc})") from exc
    mid_y = 0.5 * (p[0].get(1) + p[1].get(1))
    return SegmentParameters(
        cart_mass_kg=total - sum(masses),
        mass_kg=tuple(masses),
        inertia_kg_m2=tuple(inertias),
        length_m=tuple(lengths),
        com_x_m=tuple(coms_x),
        com_y_m=tuple(coms_y),
        attachment_m=float(-mid_y),
        gravity_m_per_s2=float(-model.getGravity().get(1)),
    )


def _foot_length(model, side: str) -> float:
    """Heel-to-toe length of the foot from its heel and first-metatarsal markers (m); 0.2 m without them."""
    ms = model.getMarkerSet()
    S = side.upper()
    try:
        h = ms.get(f"{S}HEE").get_location()
        t = ms.get(f"{S}MT1").get_location()
    except Exception:
        return 0.2
    return float((t.get(0) - h.get(0)) / 0.95)


#: Marker pairs whose distances scale each body (ScaleTool "measurements").
SCALE_MEASUREMENTS: dict[str, list[tuple[str, str]]] = {
    **{f"thigh_{s}": [(f"{s.upper()}GTR", f"{s.upper()}KNE")] for s in _LEGS},
    **{f"shank_{s}": [(f"{s.upper()}KNE", f"{s.upper()}ANK")] for s in _LEGS},
    **{f"foot_{s}": [(f"{s.upper()}HEE", f"{s.upper()}MT1")] for s in _LEGS},
    "pelvis": [("RASI", "LASI"), ("RASI", "RPSI"), ("LASI", "LPSI")],
}
