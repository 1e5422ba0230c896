"""Where the device's rods push: the thigh rod's brace and a second rod just above the ankle.

The rods push in the sagittal plane. A segment at angle ``q`` (rad, from the downward vertical, forward
positive: :func:`loper_analysis.swing_leg.dynamics.segment_coordinates`) has the forward normal
``(cos q, -sin q)`` (world x forward, y up). The thigh rod pushes along the thigh's normal; the shank rod along
the shank's normal turned by ``direction_rad`` toward the ankle (``(cos(q + a), -sin(q + a))``: a positive
angle tilts the push down the shank, a negative one up it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["SHANK_ATTACHMENT_FRACTION", "ShankRod", "segment_normal", "shank_rod_direction"]

#: A second rod's point on the shank, as a fraction of the shank's length from the knee: just above the ankle.
SHANK_ATTACHMENT_FRACTION: float = 0.85


@dataclass(frozen=True)
class ShankRod:
    """A second rod just above the ankle: its point at ``attachment_fraction`` of the shank's length from the
    knee (0 < f <= 1), its push along the shank's forward normal turned by ``direction_rad`` (rad, toward the
    ankle positive; |a| < pi/2, else the rod would pull back or push along the shank)."""

    attachment_fraction: float = SHANK_ATTACHMENT_FRACTION
    direction_rad: float = 0.0

    def __post_init__(self):
        f, a = float(self.attachment_fraction), float(self.direction_rad)
        if not (math.isfinite(f) and 0.0 < f <= 1.0):
            raise LoperInputError(
                "device.shank_rod.attachment_fraction must lie in (0, 1] (a point of the shank, as a fraction of its "
                f"length from the knee), got {self.attachment_fraction!r}"
            )
        if not (math.isfinite(a) and abs(a) < math.pi / 2):
            raise LoperInputError(
                "device.shank_rod.direction_deg must lie strictly between -90 and 90 (the push's angle from the "
                f"shank's forward normal), got {math.degrees(a):g}"
            )

    def attachment_m(self, shank_length_m: float) -> float:
        """The rod's point from the knee along the shank (m) of a shank ``shank_length_m`` m long."""
        return self.attachment_fraction * float(shank_length_m)


def segment_normal(q_rad) -> np.ndarray:
    """Unit vectors (..., 2) perpendicular to a segment at angle ``q_rad`` (rad, any shape), forward, world x/y."""
    q = np.asarray(q_rad, dtype=float)
    return np.stack([np.cos(q), -np.sin(q)], axis=-1)


def shank_rod_direction(q_shank_rad, rod: ShankRod) -> np.ndarray:
    """Unit vectors (..., 2), world x/y, along which ``rod`` pushes a shank at angle ``q_shank_rad`` (rad)."""
    return segment_normal(np.asarray(q_shank_rad, dtype=float) + rod.direction_rad)
