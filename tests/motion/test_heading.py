"""The walking direction of a trial and the rotation chosen for it (loper_analysis.motion.heading)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.heading import travel_velocity_m_per_s, trial_heading
from loper_analysis.motion.markers import rotate_markers

WALKING5 = Path(__file__).resolve().parents[1] / "data" / "opensim-core" / "walking5.c3d"
Z_UP = (-90.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def walking5():
    rec = read_c3d(WALKING5)
    return rec.markers_m, rec.point_rate_hz


def test_velocity_is_the_mean_step_of_the_present_markers():
    t = np.arange(5) / 100.0
    X = np.stack(
        [np.stack([1.2 * t, 0 * t, 0.5 + 0 * t], axis=1), np.stack([1.2 * t + 1, 0 * t, 1 + 0 * t], axis=1)], axis=1
    )
    X[2, 1] = np.nan  # a missing sample drops the two steps touching it, not the marker
    np.testing.assert_allclose(travel_velocity_m_per_s(X, 100.0), [1.2, 0.0, 0.0], rtol=1e-12)
    assert np.isnan(travel_velocity_m_per_s(np.full((3, 2, 3), np.nan), 100.0)).all()


def test_walking5_walks_minus_x_and_is_turned_half_a_turn(walking5):
    X, rate = walking5
    h = trial_heading(X, rate, Z_UP)
    assert h.source == "travel" and h.turn_deg == 180.0 and h.rotation_deg == (90.0, 0.0, 180.0)
    assert h.heading_deg == pytest.approx(182.37, abs=0.01)  # -X and 2.4 deg to the side
    assert h.speed_m_per_s == pytest.approx(1.618, abs=0.001)
    v = travel_velocity_m_per_s(rotate_markers(X, h.rotation_deg), rate)
    assert v[0] > 1.6 and abs(v[1]) < 0.01  # now forward (+X), vertical still vertical


def test_the_same_walk_in_the_other_direction_gives_the_same_markers_in_the_model(walking5):
    X, rate = walking5
    turned = X * np.array([-1.0, -1.0, 1.0])  # the lab turned half a turn about its vertical (Z): walks +X
    a, b = trial_heading(X, rate, Z_UP), trial_heading(turned, rate, Z_UP)
    assert b.turn_deg == 0.0 and b.rotation_deg == Z_UP
    np.testing.assert_allclose(
        rotate_markers(turned, b.rotation_deg), rotate_markers(X, a.rotation_deg), rtol=0, atol=1e-12
    )


def test_a_walk_along_lab_y_is_turned_a_quarter_turn(walking5):
    X, rate = walking5
    along_y = X[..., [1, 0, 2]] * np.array([1.0, -1.0, 1.0])  # lab (x, y) -> (y, -x): the walk goes along +Y
    h = trial_heading(along_y, rate, Z_UP)
    assert h.heading_deg == pytest.approx(92.37, abs=0.01)  # lab +Y is the model's -Z: 90 deg from +X
    assert h.turn_deg == 270.0
    v = travel_velocity_m_per_s(rotate_markers(along_y, h.rotation_deg), rate)
    assert v[0] > 1.6 and abs(v[2]) < 0.1


def test_a_treadmill_or_fixed_mode_keeps_the_configured_rotation(walking5):
    X, rate = walking5
    stand = np.repeat(X[600:601], 200, axis=0)  # no travel at all
    h = trial_heading(stand, rate, Z_UP)
    assert h.source == "config" and h.rotation_deg == Z_UP and h.turn_deg == 0.0 and h.speed_m_per_s == 0.0
    fixed = trial_heading(X, rate, Z_UP, mode="fixed")
    assert fixed.rotation_deg == Z_UP and fixed.source == "config"
    slow = trial_heading(X, rate, Z_UP, min_speed_m_per_s=2.0)  # 1.6 m/s does not count as travel here
    assert slow.rotation_deg == Z_UP
    with pytest.raises(LoperInputError, match=r"t\.c3d: markers\.walking_direction must be one of .*got 'north'"):
        trial_heading(X, rate, Z_UP, mode="north", source="t.c3d")


QCMAS = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "QCMAS"


def test_a_static_trial_is_turned_to_face_plus_x_by_its_pelvis_markers():
    """The clinical lab's static trial: the subject stands facing the lab's +Y, which the Z-up rotation turns to
    the model's -Z; a quarter turn faces it to +X, after which its ASIS lie in front of its PSIS."""
    from loper_analysis.motion.heading import facing_m
    from loper_analysis.motion.label_matching import landmark_indices

    rec = read_c3d(QCMAS / "static.c3d")
    names = rec.marker_labels
    front, back = landmark_indices(names, ["asis"]), landmark_indices(names, ["psis", "sacrum"])
    assert [names[i] for i in front] == ["LASI", "RASI"] and [names[i] for i in back] == ["LPSI", "RPSI"]
    h = trial_heading(rec.markers_m, rec.point_rate_hz, Z_UP, pelvis=(front, back))
    assert h.source == "pelvis" and h.turn_deg == 90.0 and h.speed_m_per_s < 0.01
    face = facing_m(rotate_markers(rec.markers_m, h.rotation_deg), front, back)
    # forward along +X (ASIS to PSIS 0.17 m), the subject standing 7 degrees off the lab's axis
    assert face[0] > 0.15 and np.degrees(np.arctan2(abs(face[2]), face[0])) == pytest.approx(7.3, abs=0.1)
    # without pelvis markers, or in fixed mode, the configured rotation stands
    assert trial_heading(rec.markers_m, rec.point_rate_hz, Z_UP).source == "config"
    assert trial_heading(rec.markers_m, rec.point_rate_hz, Z_UP, "fixed", pelvis=(front, back)).turn_deg == 0.0
