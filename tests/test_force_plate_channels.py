"""Force-platform channels of a known load (tests/force_plate_channels.py): the plate's frame from its corners, the
six channels of a force at a point worked out by hand, and the load read back from them."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_writer import ForcePlatform
from tests.force_plate_channels import plate_channels, plate_frame, plate_load, wrench_channels

CENTRE = np.array([0.3, 0.25, 0.0])
HALF = np.array([0.2, 0.3, 0.0])
#: A plate in the floor, its x along the lab's +x: y along the lab's -y and z down, as the C3D format has it.
FLOOR = ForcePlatform(
    type=2,
    corners_m=tuple(tuple(CENTRE + HALF * s) for s in ([1, -1, 0], [-1, -1, 0], [-1, 1, 0], [1, 1, 0])),
    origin_m=(0.001, 0.002, -0.04),
    channels=(1, 2, 3, 4, 5, 6),
)


def test_the_plate_frame_and_centre_come_from_the_corners():
    R, centre = plate_frame(FLOOR)
    np.testing.assert_allclose(R, np.diag([1.0, -1.0, -1.0]), atol=1e-15)
    np.testing.assert_allclose(centre, CENTRE, atol=1e-15)


def test_a_vertical_force_off_centre_with_a_free_moment_reads_as_worked_out_by_hand():
    """F = 700 N up at 0.1 m (+x) and 0.05 m (+y) from the centre, 2 N m about the vertical:
    about the centre M = (35, -70, 2) N m in the lab, (35, 70, -2) in plate coordinates, f = (0, 0, -700);
    about the sensor origin m - f x origin = (35 - 1.4, 70 + 0.7, -2) N m, written in N mm."""
    channels = plate_channels(FLOOR, [0.0, 0.0, 700.0], CENTRE + [0.1, 0.05, 0.0], free_moment_nm=2.0)
    np.testing.assert_allclose(channels, [[0.0, 0.0, -700.0, 33600.0, 70700.0, -2000.0]], atol=1e-9)
    in_metres = plate_channels(FLOOR, [0.0, 0.0, 700.0], CENTRE + [0.1, 0.05, 0.0], 2.0, point_unit="m")
    np.testing.assert_allclose(in_metres, [[0.0, 0.0, -700.0, 33.6, 70.7, -2.0]], atol=1e-12)


def test_a_moment_about_the_centre_is_the_force_at_a_point_less_the_free_moment():
    force, cop = np.array([[20.0, -15.0, 650.0]]), CENTRE + [-0.07, 0.12, 0.0]
    moment = np.cross(cop - CENTRE, force) + [0.0, 0.0, 1.5]
    np.testing.assert_allclose(
        wrench_channels(FLOOR, force, moment), plate_channels(FLOOR, force, cop, 1.5), rtol=1e-12, atol=1e-9
    )


@pytest.mark.parametrize("type_", [2, 4])
def test_the_load_is_read_back_from_the_channels(type_, rng):
    n = 50
    force = np.column_stack([rng.normal(0, 40, n), rng.normal(0, 40, n), rng.uniform(100, 900, n)])
    cop = CENTRE + np.column_stack([rng.uniform(-0.2, 0.2, n), rng.uniform(-0.3, 0.3, n), np.zeros(n)])
    free = rng.normal(0, 3, n)
    cal = np.eye(6) + 0.05 * rng.normal(size=(6, 6)) if type_ == 4 else None
    plate = ForcePlatform(
        type=type_,
        corners_m=FLOOR.corners_m,
        origin_m=FLOOR.origin_m,
        channels=FLOOR.channels,
        cal_matrix=None if cal is None else tuple(map(tuple, cal)),
    )
    load = plate_load(plate, plate_channels(plate, force, cop, free))
    np.testing.assert_allclose(load["force_n"], force, rtol=1e-10)
    np.testing.assert_allclose(load["cop_m"], cop, atol=1e-10)
    np.testing.assert_allclose(load["free_moment_nm"], free, atol=1e-9)


def test_a_zero_force_has_no_centre_of_pressure_and_a_bad_unit_or_shape_is_named():
    load = plate_load(FLOOR, np.zeros((1, 6)))
    assert np.isnan(load["cop_m"]).all() and (load["force_n"] == 0).all()
    with pytest.raises(LoperInputError, match=r"^point_unit must be one of mm, cm, m, got 'in'$"):
        plate_channels(FLOOR, [0.0, 0.0, 1.0], CENTRE, point_unit="in")
    with pytest.raises(LoperInputError, match=r"^cop_m must have shape \(n, 3\), got \(2,\)$"):
        plate_channels(FLOOR, [0.0, 0.0, 1.0], [0.0, 0.0])
