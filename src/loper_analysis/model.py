"""The generic sagittal-plane lower-body OpenSim model and the segment table it yields.

Built with the OpenSim API (no CustomJoint, which crashed from Python in
older versions; PITFALLS.md):

* ``pelvis`` on a ``PlanarJoint`` (``pelvis_tilt`` about Z, ``pelvis_tx``,
  ``pelvis_ty``); it carries head, arms and trunk (HAT) as one mass.
* per side ``s`` in {r, l}: ``thigh_s``, ``shank_s``, ``foot_s`` on
  ``PinJoint``s about Z with coordinates ``hip_flexion_s``, ``knee_flexion_s``,
  ``ankle_dorsiflexion_s``, all positive in flexion / dorsiflexion (the knee
  joint frames are turned half a turn about Y so that knee flexion is
  positive, unlike gait2392's ``knee_angle``).
* Axes: X forward, Y up, Z to the right (OpenSim's convention).
* Onto the swing-leg model (:mod:`loper_analysis.dynamics`): cart x =
  ``pelvis_tx``, the pelvis angle there is ``-pelvis_tilt``, and the joint
  angles are the coordinates themselves (checked against OpenSim's body
  positions in ``tests/test_model.py``).

Segment masses, lengths, COM and radii of gyration follow D. A. Winter,
*Biomechanics and Motor Control of Human Movement*, 4th ed., Wiley 2009,
Table 4.1 (the same numbers as
:func:`loper_analysis.dynamics.segment_parameters_from_anthropometry`).

The marker set is close to a 32-marker Qualisys lower-body set: pelvis
(RASI, LASI, RPSI, LPSI) and per leg greater trochanter, a 4-marker thigh
cluster, lateral and medial knee, a 3-marker shank cluster, lateral and
medial malleolus, heel, 1st and 5th metatarsal heads; plus two brace markers
on the left thigh (``LBRA_P``, ``LBRA_D``) whose line gives the rod force
direction and whose midpoint the rod attachment.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .errors import LoperInputError

if TYPE_CHECKING:  # the dynamics (numba kernels) load only when a segment table is made
    from .dynamics import SegmentParameters

__all__ = [
    "SIDES",
    "MARKERS",
    "BRACE_MARKERS",
    "COORDINATES",
    "build_lower_body_model",
    "segment_parameters_from_model",
    "quiet_opensim",
    "scale_model",
]

SIDES = ("r", "l")
BRACE_MARKERS = ("LBRA_P", "LBRA_D")
COORDINATES = (
    "pelvis_tilt", "pelvis_tx", "pelvis_ty",
    "hip_flexion_r", "knee_flexion_r", "ankle_dorsiflexion_r",
    "hip_flexion_l", "knee_flexion_l", "ankle_dorsiflexion_l",
)


def quiet_opensim():
    """Import opensim with logging at 'error' and no opensim.log file; returns the module."""
    import opensim

    opensim.Logger.setLevelString("error")
    opensim.Logger.removeFileSink()
    return opensim


def _anthropometry(height_m: float, mass_kg: float) -> dict:
    H, M = height_m, mass_kg
    seg = {
        "thigh": dict(mass=0.100 * M, length=0.245 * H, com=0.433, k=0.323),
        "shank": dict(mass=0.0465 * M, length=0.246 * H, com=0.433, k=0.302),
        "foot": dict(mass=0.0145 * M, length=0.152 * H, com=0.5, k=0.475),
    }
    leg = sum(s["mass"] for s in seg.values())
    pelvis_hat = M - 2 * leg
    return {
        "segments": seg,
        "pelvis_mass": pelvis_hat,
        "hat_com_height": 0.626 * 0.288 * H,  # Winter: HAT COM 0.626 of the hip-shoulder length (0.288 H)
        "hat_k": 0.496 * 0.288 * H,
        "hip_half_width": 0.05 * H,
        "pelvis_depth": 0.075 * H,
        "ankle_height": 0.039 * H,
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
    for side in SIDES:
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
            (f"{S}HEE", f"foot_{side}", (-0.2 * Lf, -0.6 * ah, 0.0)),
            (f"{S}MT1", f"foot_{side}", (0.75 * Lf, -ah, -z * 0.035)),
            (f"{S}MT5", f"foot_{side}", (0.65 * Lf, -ah, z * 0.035)),
        ]
    out += [
        ("LBRA_P", "thigh_l", (0.07, -0.72 * Lt, -0.06)),
        ("LBRA_D", "thigh_l", (0.07, -0.88 * Lt, -0.06)),
    ]
    return out


#: Marker names of the default model, in model order.
MARKERS: tuple[str, ...] = tuple(name for name, _, _ in _marker_table(_anthropometry(1.75, 70.0)))


def build_lower_body_model(height_m: float, mass_kg: float, out_path: str | Path | None = None, name: str = "loper_lower_body"):
    """Build the generic model for a subject of this height and mass; optionally print it to ``out_path`` (.osim).

    Returns the ``opensim.Model`` (system initialised).
    """
    if not 1.0 <= height_m <= 2.5:
        raise LoperInputError(f"height_m must lie in 1 .. 2.5 m, got {height_m}")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    osim = quiet_opensim()
    a = _anthropometry(float(height_m), float(mass_kg))
    model = osim.Model()
    model.setName(name)
    model.setGravity(osim.Vec3(0, -9.81, 0))
    ground = model.getGround()

    def inertia(m, k_xy, k_z):
        return osim.Inertia(m * k_xy**2, m * k_xy**2, m * k_z**2)

    pelvis = osim.Body("pelvis", a["pelvis_mass"], osim.Vec3(0, a["hat_com_height"], 0),
                       inertia(a["pelvis_mass"], a["hat_k"], a["hat_k"]))
    model.addBody(pelvis)
    pj = osim.PlanarJoint("pelvis_joint", ground, osim.Vec3(0), osim.Vec3(0), pelvis, osim.Vec3(0), osim.Vec3(0))
    for i, cname in enumerate(("pelvis_tilt", "pelvis_tx", "pelvis_ty")):
        pj.upd_coordinates(i).setName(cname)
    model.addJoint(pj)
    leg_height = a["segments"]["thigh"]["length"] + a["segments"]["shank"]["length"] + a["ankle_height"]
    pj.upd_coordinates(2).setDefaultValue(leg_height)

    for side in SIDES:
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
                com = osim.Vec3((p["com"] - 0.2) * L, -0.5 * a["ankle_height"], 0)
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
    if out_path is not None:
        model.printToXML(str(out_path))
    return model


def segment_parameters_from_model(model_or_path, side: str = "l", brace_markers=BRACE_MARKERS) -> SegmentParameters:
    """Swing-leg segment table from an OpenSim model built by :func:`build_lower_body_model` (or scaled from it).

    Masses, COM (x, y in the body frame) and the inertia about Z come from the
    bodies ``thigh_{side}``, ``shank_{side}``, ``foot_{side}``; lengths from the
    knee and ankle joint locations; the cart mass is the model mass minus the
    leg; the rod attachment is the projection of the brace markers' midpoint on
    the thigh axis.
    """
    from .dynamics import SegmentParameters

    osim = quiet_opensim()
    model = model_or_path
    if isinstance(model_or_path, (str, Path)):
        if not Path(model_or_path).is_file():
            raise LoperInputError(f"model file not found: {model_or_path}")
        model = osim.Model(str(model_or_path))
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
    **{f"thigh_{s}": [(f"{s.upper()}GTR", f"{s.upper()}KNE")] for s in SIDES},
    **{f"shank_{s}": [(f"{s.upper()}KNE", f"{s.upper()}ANK")] for s in SIDES},
    **{f"foot_{s}": [(f"{s.upper()}HEE", f"{s.upper()}MT1")] for s in SIDES},
    "pelvis": [("RASI", "LASI"), ("RASI", "RPSI"), ("LASI", "LPSI")],
}


def scale_model(generic_osim, static_trc, mass_kg: float, out_osim, time_range_s: tuple[float, float] | None = None):
    """Personalise the generic model with OpenSim's ScaleTool from a static trial (TRC).

    Each body is scaled uniformly by the ratio of the marker-pair distances in
    the static trial to those of the model (:data:`SCALE_MEASUREMENTS`); the
    mass distribution is preserved at ``mass_kg``. The static markers must be
    complete (ScaleTool crashes on NaN, PITFALLS.md): the first missing marker
    is named. Writes ``out_osim``; returns it as a Path.
    """
    osim = quiet_opensim()
    generic_osim, static_trc, out_osim = Path(generic_osim), Path(static_trc), Path(out_osim)
    for path in (generic_osim, static_trc):
        if not path.is_file():
            raise LoperInputError(f"file not found: {path}")
    if not 0 < mass_kg <= 300:
        raise LoperInputError(f"mass_kg must lie in 0 .. 300 kg, got {mass_kg}")
    table = osim.TimeSeriesTableVec3(str(static_trc))
    labels = list(table.getColumnLabels())
    times = np.array(table.getIndependentColumn())
    t0, t1 = (times[0], times[-1]) if time_range_s is None else time_range_s
    needed = sorted({m for pairs in SCALE_MEASUREMENTS.values() for pair in pairs for m in pair})
    missing = [m for m in needed if m not in labels]
    if missing:
        raise LoperInputError(f"{static_trc}: static trial lacks marker(s) {missing} needed for scaling")
    flat_table = table.flatten(osim.StdVectorString(["_x", "_y", "_z"]))  # keep the temporaries alive
    matrix = flat_table.getMatrix()
    flat = np.array(matrix.to_numpy(), copy=True)
    sel = (times >= t0 - 1e-9) & (times <= t1 + 1e-9)
    for j, lab in enumerate(labels):
        if lab in needed:
            bad = np.flatnonzero(~np.all(np.isfinite(flat[:, 3 * j : 3 * j + 3]), axis=1) & sel)
            if bad.size:
                raise LoperInputError(
                    f"{static_trc}: marker {lab} is missing at frame {bad[0]} (t = {times[bad[0]]:.3f} s) of the "
                    "static trial; fill the gap or choose another time range"
                )
    tool = osim.ScaleTool()
    tool.setSubjectMass(float(mass_kg))
    tool.getGenericModelMaker().setModelFileName(str(generic_osim))
    scaler = tool.getModelScaler()
    scaler.setApply(True)
    order = osim.ArrayStr()
    order.append("measurements")
    scaler.setScalingOrder(order)
    scaler.setMarkerFileName(str(static_trc))
    tr = osim.ArrayDouble()
    tr.append(float(t0))
    tr.append(float(t1))
    scaler.setTimeRange(tr)
    scaler.setPreserveMassDist(True)
    measurements = scaler.getMeasurementSet()
    for body, pairs in SCALE_MEASUREMENTS.items():
        m = osim.Measurement()
        m.setName(body)
        m.setApply(True)
        for a, b in pairs:
            m.getMarkerPairSet().cloneAndAppend(osim.MarkerPair(a, b))
        scale = osim.BodyScale()
        scale.setName(body)
        axes = osim.ArrayStr()
        for axis in "XYZ":
            axes.append(axis)
        scale.setAxisNames(axes)
        m.getBodyScaleSet().cloneAndAppend(scale)
        measurements.cloneAndAppend(m)
    tmp = out_osim.with_name(f".{out_osim.name}.partial.osim")
    tmp.unlink(missing_ok=True)
    scaler.setOutputModelFileName(str(tmp))
    tool.getMarkerPlacer().setApply(False)
    tool.run()  # returns False when the marker placer is off, even after a good scaling: check the file
    if not tmp.is_file():
        raise LoperInputError(f"OpenSim ScaleTool failed for {static_trc} with {generic_osim}")
    os.replace(tmp, out_osim)
    return out_osim
