"""Shared test data: segment parameter sets."""

from loper_analysis.swing_leg.dynamics import (
    SegmentParameters,
    segment_parameters_from_anthropometry,
)

WINTER = segment_parameters_from_anthropometry(1.73, 64.9)
# COM off the segment axes and a non-standard gravity exercise every term
ASYMMETRIC = SegmentParameters(
    cart_mass_kg=41.3,
    mass_kg=(7.9, 3.4, 1.1),
    inertia_kg_m2=(0.151, 0.047, 0.0062),
    length_m=(0.43, 0.41, 0.26),
    com_x_m=(0.021, -0.013, 0.064),
    com_y_m=(-0.185, -0.172, -0.031),
    attachment_m=0.29,
    gravity_m_per_s2=9.79,
)
