"""Points against a force plate (gait.plate_geometry): the plate's centre and axes from its corners, and a point's
horizontal distance outside the plate and height above it, against hand-computed answers on a level plate, a
trapezoid and the same plate turned by a random rotation; bad corners, axes and points named."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.plate_geometry import plate_axes, plate_offsets

# plate 1 under the left belt, plate 2 under the right one (walking along +y, surface z = 0)
CORNERS = {
    1: np.array([[-0.50, 0.0, 0.0], [-0.01, 0.0, 0.0], [-0.01, 1.6, 0.0], [-0.50, 1.6, 0.0]]),
    2: np.array([[0.01, 0.0, 0.0], [0.50, 0.0, 0.0], [0.50, 1.6, 0.0], [0.01, 1.6, 0.0]]),
}
#: A trapezoid in z = 0: base 0 .. 2 m, top 0.5 .. 1.5 m at y = 1 m.
TRAPEZOID = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.5, 1.0, 0.0], [0.5, 1.0, 0.0]])


def test_plate_offsets_inside_outside_and_height():
    c = CORNERS[2]
    out, up = plate_offsets([[0.2, 0.5, 0.07], [0.6, 0.5, 0.0], [0.7, 1.9, 0.1], [np.nan, 0, 0]], c)
    np.testing.assert_allclose(out[:3], [0.0, 0.1, math.hypot(0.2, 0.3)], atol=1e-12)
    np.testing.assert_allclose(up[:3], [0.07, 0.0, 0.1], atol=1e-12)
    assert np.isnan(out[3]) and np.isnan(up[3])
    # a plate tilted into a Y-up frame (X forward, Z right) gives the same answers
    rot = np.array([[1, 0, 0], [0, 0, 1], [0, -1, 0]], dtype=float)  # lab Z up -> model Y up
    out2, up2 = plate_offsets(np.array([[0.2, 0.5, 0.07], [0.6, 0.5, 0.0]]) @ rot.T, c @ rot.T)
    np.testing.assert_allclose(out2, [0.0, 0.1], atol=1e-12)
    np.testing.assert_allclose(up2, [0.07, 0.0], atol=1e-12)
    out3, up3 = plate_offsets(np.array([[0.6, 0.5, 0.0]]) @ rot.T, c @ rot.T, vertical_axis=1)
    np.testing.assert_allclose([out3[0], up3[0]], [0.1, 0.0], atol=1e-12)
    with pytest.raises(LoperInputError, match="enclose no area"):
        plate_offsets([[0, 0, 0]], np.zeros((4, 3)))


def test_axes_of_a_level_plate_either_way_round():
    """Plate 2: centre (0.255, 0.8, 0), u along its first edge, n up (+z) listed either way round or starting at
    another corner, down along a given up (0, 0, -1); v = n x u."""
    centre, axes = plate_axes(CORNERS[2], None, "plate 2")
    np.testing.assert_allclose(centre, [0.255, 0.8, 0.0], atol=1e-15)
    np.testing.assert_allclose(axes, np.eye(3), atol=1e-15)
    centre, axes = plate_axes(CORNERS[2][::-1], None, "plate 2")  # first edge from (0.01, 1.6) to (0.5, 1.6)
    np.testing.assert_allclose(axes, np.eye(3), atol=1e-15)  # the normal's largest component turned positive
    centre, axes = plate_axes(np.roll(CORNERS[2], -1, axis=0), None, "plate 2")  # first edge (0.5, 0)-(0.5, 1.6)
    np.testing.assert_allclose(centre, [0.255, 0.8, 0.0], atol=1e-15)
    np.testing.assert_allclose(axes, [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15)
    down = plate_axes(CORNERS[2][::-1], None, "plate 2", up=(0, 0, -1))[1]  # turned along a given up
    np.testing.assert_allclose(down, [[1, 0, 0], [0, -1, 0], [0, 0, -1]], atol=1e-15)
    np.testing.assert_allclose(plate_axes(CORNERS[2], 2, "plate 2")[1], np.eye(3), atol=1e-15)


def test_a_turned_plate_keeps_its_axes_and_its_offsets(rng):
    """The plate and points turned by a random rotation R and shifted: axes R's columns (n along R e_z given as up),
    offsets those of the level plate."""
    R = Rotation.random(random_state=rng).as_matrix()
    shift = rng.normal(size=3)
    c = CORNERS[1] @ R.T + shift
    centre, axes = plate_axes(c, None, "turned", up=R[:, 2])
    np.testing.assert_allclose(centre, CORNERS[1].mean(axis=0) @ R.T + shift, atol=1e-12)
    np.testing.assert_allclose(axes, R.T, atol=1e-12)
    assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-12)
    points = np.array([[-0.3, 0.4, 0.05], [-0.6, 0.8, -0.02], [0.2, -0.4, 0.3]])
    out, height = plate_offsets(points @ R.T + shift, c, up=R[:, 2])
    np.testing.assert_allclose(out, [0.0, 0.1, math.hypot(0.21, 0.4)], atol=1e-12)
    np.testing.assert_allclose(height, [0.05, 0.02, 0.3], atol=1e-12)


def test_distance_to_a_slanted_edge_of_a_trapezoid():
    """(2, 1) lies 1/sqrt(5) m from the slanted edge (2, 0)-(1.5, 1), nearer than the corner (1.5, 1) at 0.5 m;
    (1, 0.5) is inside; (1, -0.25) is 0.25 m below the base."""
    out, height = plate_offsets([[2.0, 1.0, 0.3], [1.0, 0.5, -0.1], [1.0, -0.25, 0.0]], TRAPEZOID)
    np.testing.assert_allclose(out, [1 / math.sqrt(5), 0.0, 0.25], atol=1e-12)
    np.testing.assert_allclose(height, [0.3, 0.1, 0.0], atol=1e-12)
    one, _ = plate_offsets([2.0, 1.0, 0.3], TRAPEZOID)  # one point (3,)
    assert one.shape == (1,) and one[0] == pytest.approx(1 / math.sqrt(5), abs=1e-12)


@pytest.mark.parametrize(
    "corners, axis, message",
    [
        (CORNERS[2][:3], None, r"^walk01 plate 2: corners_m must be a finite \(4, 3\) array, got shape \(3, 3\)$"),
        (CORNERS[2], 3, r"^walk01 plate 2: vertical_axis must be 0, 1 or 2, got 3$"),
        (CORNERS[2], -1, r"^walk01 plate 2: vertical_axis must be an integer >= 0"),
        (CORNERS[2], 0, r"^walk01 plate 2: corners_m: the first edge is vertical or empty: \[\[0.01, 0.0, 0.0\]"),
    ],
)
def test_bad_corners_and_axes_are_named(corners, axis, message):
    with pytest.raises(LoperInputError, match=message):
        plate_axes(corners, axis, "walk01 plate 2")


def test_points_of_a_bad_shape_are_named():
    with pytest.raises(LoperInputError, match=r"^walk01: points_m must have shape \(k, 3\), got \(2, 2\)$"):
        plate_offsets([[0.0, 0.0], [1.0, 1.0]], CORNERS[2], source="walk01")
