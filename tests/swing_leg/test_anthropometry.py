"""Winter's anthropometric table (swing_leg.anthropometry) against the book: Table 4.1's segment rows and the
landmark heights of its Fig. 4.1 (greater trochanter 0.530 H, knee 0.285 H, ankle 0.039 H, shoulder 0.818 H), and
the standing hip height they give."""

from __future__ import annotations

import dataclasses

import pytest

from loper_analysis.swing_leg.anthropometry import (
    ANKLE_HEIGHT_FRACTION,
    HAT_COM_FRACTION,
    HAT_GYRATION_FRACTION,
    HIP_TO_SHOULDER_FRACTION,
    WINTER_SEGMENTS,
    SegmentFractions,
    leg_length_m,
)

#: Winter (2009) Fig. 4.1: heights above the floor as fractions of body height.
TROCHANTER, KNEE, ANKLE, SHOULDER = 0.530, 0.285, 0.039, 0.818


def test_segment_rows_are_winter_s_table_4_1():
    """Mass fraction, centre of mass from the proximal end and radius of gyration about it, as printed; the
    lengths are the differences of the landmark heights (the foot's is the book's 0.152 H)."""
    assert WINTER_SEGMENTS == {
        "thigh": SegmentFractions(mass=0.100, length=0.245, com=0.433, gyration=0.323),
        "shank": SegmentFractions(mass=0.0465, length=0.246, com=0.433, gyration=0.302),
        "foot": SegmentFractions(mass=0.0145, length=0.152, com=0.50, gyration=0.475),
    }
    assert WINTER_SEGMENTS["thigh"].length == pytest.approx(TROCHANTER - KNEE, abs=1e-12)
    assert WINTER_SEGMENTS["shank"].length == pytest.approx(KNEE - ANKLE, abs=1e-12)
    assert ANKLE_HEIGHT_FRACTION == ANKLE


def test_hat_row_is_winter_s():
    """Head, arms and trunk: hip to shoulder 0.818 H - 0.530 H, centre of mass 0.626 of it from the hip, radius of
    gyration 0.496 of it."""
    assert HIP_TO_SHOULDER_FRACTION == pytest.approx(SHOULDER - TROCHANTER, abs=1e-12)
    assert (HAT_COM_FRACTION, HAT_GYRATION_FRACTION) == (0.626, 0.496)


@pytest.mark.parametrize("height_m", [1.50, 1.73, 1.95])
def test_leg_length_is_the_trochanter_height(height_m):
    """Thigh + shank + ankle height = the greater trochanter's 0.530 H: 0.9169 m for 1.73 m."""
    assert leg_length_m(height_m) == pytest.approx(TROCHANTER * height_m, rel=1e-12)
    assert leg_length_m(str(height_m)) == leg_length_m(height_m)


def test_leg_length_of_a_known_height():
    assert leg_length_m(1.73) == pytest.approx(0.9169, abs=1e-12)


def test_a_row_cannot_be_changed():
    with pytest.raises(dataclasses.FrozenInstanceError):
        WINTER_SEGMENTS["thigh"].mass = 0.2
