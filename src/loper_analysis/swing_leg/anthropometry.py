"""Winter's anthropometric table: segment masses, lengths, centres of mass and radii of gyration.

D. A. Winter, *Biomechanics and Motor Control of Human Movement*, 4th ed.,
Wiley 2009, Table 4.1, as fractions of body mass (M) and height (H). The
generic OpenSim model (:mod:`loper_analysis.motion.model`), the segment table from
height and mass (:func:`loper_analysis.swing_leg.dynamics.segment_parameters_from_anthropometry`)
and the synthetic gait (:mod:`loper_analysis.synthetic.walking`) all read
their numbers here.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "SegmentFractions",
    "WINTER_SEGMENTS",
    "ANKLE_HEIGHT_FRACTION",
    "HEEL_BEHIND_ANKLE_FRACTION",
    "HAT_COM_FRACTION",
    "HIP_TO_SHOULDER_FRACTION",
    "HAT_GYRATION_FRACTION",
    "HIP_HALF_WIDTH_FRACTION",
    "PELVIS_DEPTH_FRACTION",
    "leg_length_m",
]


@dataclass(frozen=True)
class SegmentFractions:
    """One row of the table.

    Attributes
    ----------
    mass : float
        Segment mass, fraction of body mass.
    length : float
        Segment length, fraction of body height (foot: heel to toe).
    com : float
        Centre of mass from the proximal joint, fraction of the segment length
        (foot: from the heel along the foot).
    gyration : float
        Radius of gyration about the centre of mass, fraction of the segment length.
    """

    mass: float
    length: float
    com: float
    gyration: float


#: Thigh, shank ("leg" in the table) and foot.
WINTER_SEGMENTS: dict[str, SegmentFractions] = {
    "thigh": SegmentFractions(mass=0.100, length=0.245, com=0.433, gyration=0.323),
    "shank": SegmentFractions(mass=0.0465, length=0.246, com=0.433, gyration=0.302),
    "foot": SegmentFractions(mass=0.0145, length=0.152, com=0.50, gyration=0.475),
}
#: Height of the ankle joint above the sole, fraction of body height.
ANKLE_HEIGHT_FRACTION: float = 0.039
#: The heel lies this fraction of the foot length behind the ankle joint (our foot geometry).
HEEL_BEHIND_ANKLE_FRACTION: float = 0.2
#: Head, arms and trunk (HAT): centre of mass above the hip, fraction of the hip-to-shoulder length.
HAT_COM_FRACTION: float = 0.626
#: Hip-to-shoulder length, fraction of body height.
HIP_TO_SHOULDER_FRACTION: float = 0.288
#: HAT radius of gyration about its centre of mass, fraction of the hip-to-shoulder length.
HAT_GYRATION_FRACTION: float = 0.496
#: Half the distance between the hip joints, fraction of body height (our pelvis geometry).
HIP_HALF_WIDTH_FRACTION: float = 0.05
#: Pelvis depth (front to back), fraction of body height (our pelvis geometry).
PELVIS_DEPTH_FRACTION: float = 0.075


def leg_length_m(height_m: float) -> float:
    """Standing hip-joint height (m) for a body height (m): thigh + shank + ankle height."""
    H = float(height_m)
    return WINTER_SEGMENTS["thigh"].length * H + WINTER_SEGMENTS["shank"].length * H + ANKLE_HEIGHT_FRACTION * H
