"""motion/lab_frame.py: the lab's vertical, the walking direction and the rotation into the model frame, on
marker sets and plates whose lab frame is known by construction."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.force_platforms import ForcePlatform
from loper_analysis.motion.lab_frame import (
    axis_name,
    corner_normal,
    lab_to_model_rotation_deg,
    vertical_axis,
    walking_direction,
)
from loper_analysis.motion.markers import rotate_markers

RATE_HZ = 100.0
SPEED_M_PER_S = 1.2
#: Corners of a 0.6 x 0.4 m plate in a Z-up lab listed clockwise seen from above (the C3D order).
CLOCKWISE_Z_UP = np.array([(1.3, 0.1, 0.0), (0.7, 0.1, 0.0), (0.7, 0.5, 0.0), (1.3, 0.5, 0.0)])


def _model_walker(n_frames: int = 200) -> np.ndarray:
    """(n, 5, 3) m in the model frame (X forward, Y up, Z right): head, pelvis, knee, heel, toe walking +X."""
    t = np.arange(n_frames) / RATE_HZ
    rows = [(0.0, 1.7, 0.0), (0.05, 0.95, 0.12), (0.1, 0.5, 0.1), (-0.05, 0.05, 0.1), (0.15, 0.03, -0.1)]
    X = np.zeros((n_frames, len(rows), 3))
    for j, (fwd, up, right) in enumerate(rows):
        X[:, j] = np.column_stack([SPEED_M_PER_S * t + fwd, np.full(n_frames, up), np.full(n_frames, right)])
    return X


def _plate(corners, force_z_n: float, axis: int = 2) -> ForcePlatform:
    t = np.arange(100) / 1000.0
    force = np.zeros((100, 3))
    force[:, axis] = force_z_n * np.sin(np.pi * t / t[-1])
    corners = np.asarray(corners, float)
    return ForcePlatform(1, 2, (1, 2, 3, 4, 5, 6), 1000.0, t, force, np.zeros((100, 3)), corners, corners.mean(0))


# moved unchanged from the inspection tests
@pytest.mark.parametrize("up_axis", [0, 1, 2])
@pytest.mark.parametrize("up_sign", [1, -1])
def test_rotation_takes_up_to_model_y_and_walking_to_model_x(up_axis, up_sign):
    up = np.eye(3)[up_axis] * up_sign
    angles = lab_to_model_rotation_deg(up_axis, up_sign)
    np.testing.assert_allclose(rotate_markers(up, angles), [0, 1, 0], atol=1e-12)
    for forward_axis in {0, 1, 2} - {up_axis}:
        for forward_sign in (1, -1):
            angles = lab_to_model_rotation_deg(up_axis, up_sign, forward_axis, forward_sign)
            forward = np.eye(3)[forward_axis] * forward_sign
            np.testing.assert_allclose(
                rotate_markers(np.stack([up, forward]), angles), [[0, 1, 0], [1, 0, 0]], atol=1e-12
            )


def test_rotation_known_values():
    assert lab_to_model_rotation_deg(2, 1) == (-90.0, 0.0, 0.0)
    assert lab_to_model_rotation_deg(2, 1, 0, 1) == (-90.0, 0.0, 0.0)
    assert lab_to_model_rotation_deg(2, 1, 0, -1) == (-90.0, 180.0, 0.0)
    assert lab_to_model_rotation_deg(1, 1) == (0.0, 0.0, 0.0)
    assert lab_to_model_rotation_deg(1, 1, 0, 1) == (0.0, 0.0, 0.0)


# new


@pytest.mark.parametrize(
    "to_lab, up, forward",
    [
        # Z-up lab walking -Y: lab (x, y, z) = (-Z, -X, Y) of the model
        (lambda m: np.stack([-m[..., 2], -m[..., 0], m[..., 1]], axis=-1), (2, 1), (1, -1)),
        # Y-down lab walking +Z: lab (x, y, z) = (Z, -Y, X) of the model
        (lambda m: np.stack([m[..., 2], -m[..., 1], m[..., 0]], axis=-1), (1, -1), (2, 1)),
        # X-up lab walking +Y: lab (x, y, z) = (Y, X, -Z)
        (lambda m: np.stack([m[..., 1], m[..., 0], -m[..., 2]], axis=-1), (0, 1), (1, 1)),
    ],
)
def test_a_lab_recording_rotates_back_onto_the_model_coordinates(to_lab, up, forward):
    model = _model_walker()
    lab = to_lab(model)
    v = vertical_axis(lab)
    assert (v.axis, v.sign, v.basis) == (*up, "markers")
    w = walking_direction(lab, RATE_HZ, v.axis)
    assert (w.axis, w.sign) == forward
    np.testing.assert_allclose(w.speed_m_per_s, SPEED_M_PER_S, rtol=1e-12)
    np.testing.assert_allclose(w.travel_m[w.axis], w.sign * SPEED_M_PER_S * 199 / RATE_HZ, rtol=1e-12)
    angles = lab_to_model_rotation_deg(v.axis, v.sign, w.axis, w.sign)
    np.testing.assert_allclose(rotate_markers(lab, angles), model, atol=1e-12)


def test_axis_names():
    assert [axis_name(2), axis_name(0, -1), axis_name(1, 0), axis_name(None)] == ["+Z", "-X", "+Y", "none"]


def test_corner_normal_follows_the_corner_order():
    np.testing.assert_allclose(corner_normal(CLOCKWISE_Z_UP), [0, 0, -1], atol=1e-15)
    np.testing.assert_allclose(corner_normal(CLOCKWISE_Z_UP[::-1]), [0, 0, 1], atol=1e-15)
    tilted = CLOCKWISE_Z_UP.copy()
    tilted[:, 2] = tilted[:, 0] * 1.0  # rises 1 m per m along x: the normal leans 45 degrees
    np.testing.assert_allclose(corner_normal(tilted), np.array([1, 0, -1]) / np.sqrt(2), atol=1e-15)
    assert np.isnan(corner_normal(np.zeros((4, 3)))).all()
    with pytest.raises(LoperInputError, match=r"^force platform: corners must have shape \(4, 3\), got \(3, 3\)$"):
        corner_normal(CLOCKWISE_Z_UP[:3])


def test_plates_decide_the_vertical_over_the_markers():
    model = _model_walker()
    markers = np.stack([-model[..., 2], model[..., 0], model[..., 1]], axis=-1)  # Z-up lab walking +Y
    # a loaded plate whose force on the body points -Z: the lab's up is -Z, whatever the markers say
    v = vertical_axis(markers, [_plate(CLOCKWISE_Z_UP, -800.0)])
    assert (v.axis, v.sign, v.basis, v.marker_axis, v.marker_sign) == (2, -1, "force platforms", 2, 1)
    # spread of a frame: right 0.12 - (-0.1), forward 0.15 - (-0.05), up 1.7 - 0.03
    np.testing.assert_allclose(v.marker_spread_m, [0.22, 0.20, 1.67], atol=1e-12)
    # a plate loaded below min_load_n tells the axis only; its sign is the markers'
    v = vertical_axis(markers, [_plate(CLOCKWISE_Z_UP, -50.0)])
    assert (v.axis, v.sign, v.basis) == (2, 1, "force platforms")
    # plates on two axes settle nothing: the markers decide
    wall = CLOCKWISE_Z_UP[:, [0, 2, 1]]
    v = vertical_axis(markers, [_plate(CLOCKWISE_Z_UP, 800.0), _plate(wall, 800.0, axis=1)])
    assert (v.axis, v.sign, v.basis) == (2, 1, "markers")


def test_without_plates_or_three_markers_z_up_is_assumed():
    sparse = np.full((10, 3, 3), np.nan)
    sparse[:, :2] = 1.0
    v = vertical_axis(sparse)
    assert (v.axis, v.sign, v.basis, v.marker_axis, v.marker_spread_m) == (2, 1, "assumed", None, None)


def test_a_treadmill_or_an_empty_recording_does_not_travel():
    model = _model_walker()
    model[..., 0] -= SPEED_M_PER_S * np.arange(200)[:, None] / RATE_HZ
    w = walking_direction(model, RATE_HZ, 1)
    assert (w.axis, w.sign) == (None, 0) and np.isnan(w.speed_m_per_s)
    np.testing.assert_allclose(w.travel_m, 0.0, atol=1e-12)
    w = walking_direction(np.full((5, 2, 3), np.nan), RATE_HZ, 1)
    assert w.axis is None and np.isnan(w.travel_m).all()


def test_bad_axes_and_rates_are_refused():
    with pytest.raises(LoperInputError, match=r"^markers: up_axis must be 0, 1 or 2, got 3$"):
        walking_direction(_model_walker(), RATE_HZ, 3)
    with pytest.raises(LoperInputError, match=r"^markers: point_rate_hz must be positive, got 0$"):
        walking_direction(_model_walker(), 0, 1)
    with pytest.raises(LoperInputError, match=r"^rotation: the walking direction cannot be the vertical axis Y$"):
        lab_to_model_rotation_deg(1, 1, 1, 1)
    with pytest.raises(LoperInputError, match=r"^rotation: signs must be \+1 or -1, got 0, 1$"):
        lab_to_model_rotation_deg(1, 0)
