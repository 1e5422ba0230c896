"""Names shared by the library, the rules and the tables."""

from __future__ import annotations

__all__ = [
    "JOINTS",
    "COORDINATES",
    "SEGMENTS",
    "PARAMETERS",
    "PARAMETER_UNITS",
    "GRAVITY_M_PER_S2",
]

#: Joints of the swing leg, in model order.
JOINTS: tuple[str, ...] = ("hip", "knee", "ankle")
#: Generalised coordinates of the swing-leg model (cart x in m, segment angles in rad).
COORDINATES: tuple[str, ...] = ("pelvis_x", "thigh", "shank", "foot")
#: Rigid segments of the swing leg, proximal to distal.
SEGMENTS: tuple[str, ...] = ("thigh", "shank", "foot")
#: Identified parameters, in the order of every parameter vector.
PARAMETERS: tuple[str, ...] = ("K_hip", "D_hip", "K_knee", "D_knee", "K_ankle", "D_ankle")
#: Units of the identified parameters.
PARAMETER_UNITS: dict[str, str] = {
    p: ("N·m/rad" if p.startswith("K") else "N·m·s/rad") for p in PARAMETERS
}
GRAVITY_M_PER_S2: float = 9.81
