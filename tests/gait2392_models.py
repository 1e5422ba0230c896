"""gait2392 (``examples/gait2392/``) as distributed with its scale markers, and scaled with known factors, for
the tests of IK, scaling and segment tables."""

from __future__ import annotations

from pathlib import Path

from loper_analysis.io.osim import quiet_opensim, read_marker_set, read_model

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "gait2392"
GENERIC = EXAMPLE / "gait2392_simbody.osim"
MARKER_SET = EXAMPLE / "gait2392_Scale_MarkerSet.xml"
#: gait2392's total mass (kg): a subject of this mass keeps the model's body masses.
GENERIC_MASS_KG = 75.1646


def gait2392_with_markers():
    """gait2392 as distributed, with its scale marker set attached, initialised (``opensim.Model``)."""
    model = read_model(GENERIC)
    model.updateMarkerSet(read_marker_set(MARKER_SET))
    model.initSystem()
    return model


def scaled_gait2392(factors: dict[str, float], mass_kg: float, markers: bool = False):
    """gait2392 scaled uniformly per body with OpenSim's ``Model.scale`` to ``mass_kg`` (mass distribution kept).

    ``factors`` maps a body (``pelvis``, ``torso``) or a body pair without its
    side suffix (``femur``, ``tibia``, ``talus``, ...) to its factor;
    ``markers`` adds the scale marker set first. Returns the ``opensim.Model``.
    """
    osim = quiet_opensim()
    model = read_model(GENERIC)
    if markers:
        model.updateMarkerSet(read_marker_set(MARKER_SET))
    state = model.initSystem()
    scales = osim.ScaleSet()
    for body, f in factors.items():
        for name in [body] if body in ("pelvis", "torso") else [f"{body}_r", f"{body}_l"]:
            s = osim.Scale()
            s.setSegmentName(name)
            s.setScaleFactors(osim.Vec3(f, f, f))
            s.setApply(True)
            scales.cloneAndAppend(s)
    model.scale(state, scales, True, mass_kg)
    return model
