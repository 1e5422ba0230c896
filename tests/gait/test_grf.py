"""Ground reaction: resting level, COP and free moment against OpenSim's reading of walking5.c3d and analytic loads."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf import (
    centre_of_pressure,
    external_loads_columns,
    external_loads_table,
    plate_loads,
    resting_level,
    surface_normal,
    vertical_loads,
)
from loper_analysis.io.force_platforms import read_force_platforms
from tests.io.test_force_platforms import WALKING5, reference_grfs

THRESHOLD_N = 20.0


@pytest.fixture(scope="module")
def walking5_loads():
    return [
        plate_loads(p.number, p.time_s, p.force_n, p.moment_nm, p.corners_m, threshold_n=THRESHOLD_N)
        for p in read_force_platforms(WALKING5)
    ]


def test_walking5_resting_level(walking5_loads):
    """The resting vertical level is the unloaded plates' reading; the offset-free unloaded force is near 0."""
    rest = [p.rest_force_n[2] for p in walking5_loads]
    assert rest == pytest.approx([-14.2, -18.1], abs=0.1)
    for p in walking5_loads:
        quiet = ~p.loaded
        assert abs(np.median(p.force_n[quiet, 2])) < 0.5
    # one stance per plate, without noise blips: 1.960-2.477 s and 2.374-2.976 s above 20 N
    for p, (on, off) in zip(walking5_loads, [(1.960, 2.477), (2.374, 2.976)]):
        assert np.count_nonzero(np.diff(p.loaded.astype(int))) == 2
        t = p.time_s[p.loaded]
        assert t[0] == pytest.approx(on, abs=0.001) and t[-1] == pytest.approx(off, abs=0.001)


def test_walking5_against_opensim_reference(walking5_loads):
    """std_walking5_grfs.sto is not zeroed: our resting level is removed from it too, then COP and free
    moment are derived from it with the textbook formulas of a level plate (x = -My/Fz, y = Mx/Fz)."""
    t, ref = reference_grfs()
    table = external_loads_table(walking5_loads, (0.0, 0.0, 0.0))
    n_loaded = 0
    for p in walking5_loads:
        idx = np.searchsorted(p.time_s, t - 1e-9)
        r = ref[:, p.number - 1]
        f = r[:, 0:3] - p.rest_force_n
        m = r[:, 6:9] - p.rest_moment_nm * 1000.0  # N·mm about the surface centre r[:, 3:6]
        # force, every row, before the unloaded policy
        assert np.max(np.abs(p.force_n[idx] - f)) < 0.05
        loaded = p.loaded[idx]
        assert loaded.sum() >= 9
        n_loaded += int(loaded.sum())
        cop_x = r[:, 3] - m[:, 1] / f[:, 2]
        cop_y = r[:, 4] + m[:, 0] / f[:, 2]
        tz = (m[:, 2] - ((cop_x - r[:, 3]) * f[:, 1] - (cop_y - r[:, 4]) * f[:, 0])) / 1000.0
        cols = external_loads_columns(p.number)
        rows = table.iloc[idx[loaded]]
        assert np.max(np.abs(rows[cols[0:3]].to_numpy() - f[loaded])) < 0.05
        assert np.max(np.abs(rows[cols[3]].to_numpy() * 1000.0 - cop_x[loaded])) < 0.5
        assert np.max(np.abs(rows[cols[4]].to_numpy() * 1000.0 - cop_y[loaded])) < 0.5
        assert np.max(np.abs(rows[cols[5]].to_numpy())) < 1e-12  # on the surface, z = 0
        assert np.max(np.abs(rows[cols[8]].to_numpy() - tz[loaded])) < 0.05
        np.testing.assert_array_equal(rows[cols[6:8]].to_numpy(), 0.0)
        # unloaded rows: force and torque exactly 0
        quiet = table.iloc[idx[~loaded]]
        np.testing.assert_array_equal(quiet[cols[0:3] + cols[6:9]].to_numpy(), 0.0)
    assert n_loaded == 22  # 10 rows of plate 1 (2.00-2.45 s), 12 of plate 2 (2.40-2.95 s)


def test_cop_never_jumps_at_touch_down_or_lift_off(walking5_loads):
    p = walking5_loads[0]
    edges = np.flatnonzero(np.diff(p.loaded.astype(int)))
    for e in edges:
        np.testing.assert_array_equal(p.cop_m[e], p.cop_m[e + 1])
    step = np.max(np.linalg.norm(np.diff(p.cop_m, axis=0), axis=1))
    assert step < 0.05  # largest sample-to-sample move, m (raw 2000 Hz COP while loaded)


def test_cop_and_free_moment_of_a_tilted_plate():
    """Generic formula: a plate tilted 20 degrees about x, point load plus free moment about its normal."""
    a = np.radians(20.0)
    n = np.array([0.0, -np.sin(a), np.cos(a)])
    centre = np.array([0.4, 0.3, 0.05])
    u = np.array([1.0, 0.0, 0.0])
    v = np.cross(n, u)
    cop = centre + 0.12 * u - 0.07 * v
    F = np.array([[25.0, 40.0, 650.0], [-10.0, 5.0, 300.0]])
    T = np.array([2.5, -1.0])
    M = np.cross(cop - centre, F) + T[:, None] * n
    got_cop, got_T = centre_of_pressure(F, M, centre, n)
    np.testing.assert_allclose(got_cop, np.tile(cop, (2, 1)), atol=1e-12)
    np.testing.assert_allclose(got_T, T, atol=1e-12)


def test_surface_normal_points_up_for_either_corner_order():
    c = np.array([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(surface_normal(c), [0, 0, 1])
    np.testing.assert_allclose(surface_normal(c[::-1]), [0, 0, 1])
    wall = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    with pytest.raises(LoperInputError, match="does not face up"):
        surface_normal(wall, "wall.c3d")


def _synthetic(n_rest=200, n_load=100, rest=(1.0, -2.0, -60.0), noise=0.0, seed=0):
    rng = np.random.default_rng(seed)
    F = np.tile(rest, (n_rest + n_load, 1)).astype(float)
    F[n_rest:] += [10.0, 5.0, 500.0]
    F += noise * rng.standard_normal(F.shape)
    M = np.zeros_like(F)
    M[:, 0] = 3.0
    return F, M


def test_resting_level_median_of_unloaded_samples():
    F, M = _synthetic(noise=2.0)
    rest_f, rest_m, unloaded = resting_level(F, M, band_n=10.0)
    assert unloaded[:200].mean() > 0.99 and not unloaded[200:].any()
    np.testing.assert_allclose(rest_f, [1.0, -2.0, -60.0], atol=0.5)
    np.testing.assert_allclose(rest_m, [3.0, 0.0, 0.0], atol=1e-12)


def test_plate_loaded_throughout_is_refused():
    F, M = _synthetic(n_rest=0, n_load=50)
    with pytest.raises(LoperInputError, match=r"trial\.c3d: resting vertical force 440\.0 N exceeds 100 N"):
        resting_level(F, M, source="trial.c3d")


def test_force_on_the_plate_instead_of_the_body_is_refused():
    F, M = _synthetic()
    with pytest.raises(LoperInputError, match="force points down while loaded"):
        resting_level(-F, M)


def test_unloaded_policy_cop_nearest_loaded_and_zero_free_moment():
    corners = np.array([[0.5, 0.0, 0.0], [0.5, 0.4, 0.0], [0.0, 0.4, 0.0], [0.0, 0.0, 0.0]])
    centre = corners.mean(axis=0)
    n = 11
    F = np.zeros((n, 3))
    F[3:5, 2] = 400.0  # first contact at samples 3-4, COP x = centre + 0.1
    F[8:9, 2] = 400.0  # second contact at sample 8, COP x = centre - 0.1
    M = np.zeros((n, 3))
    M[3:5, 1] = -0.1 * 400.0
    M[8, 1] = 0.1 * 400.0
    M[3:5, 2] = 1.0
    loads = plate_loads(1, np.arange(n) / 100.0, F, M, corners, threshold_n=20.0)
    x = loads.cop_m[:, 0] - centre[0]
    np.testing.assert_allclose(x, [0.1] * 7 + [-0.1] * 4, atol=1e-12)  # sample 6 is as near 4 as 8: the earlier wins
    np.testing.assert_allclose(loads.free_moment_nm, [0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0], atol=1e-12)
    never = plate_loads(2, np.arange(n) / 100.0, np.zeros((n, 3)), M * 0, corners)
    np.testing.assert_array_equal(never.cop_m, np.tile(centre, (n, 1)))


def test_table_rotation_and_vertical_loads(walking5_loads):
    lab = external_loads_table(walking5_loads, (0.0, 0.0, 0.0))
    model = external_loads_table(walking5_loads, (-90.0, 0.0, 0.0))
    for k in (1, 2):
        c = external_loads_columns(k)
        # (x, y, z) -> (x, z, -y) for force, point and torque
        for j in (0, 3, 6):
            np.testing.assert_allclose(model[c[j]], lab[c[j]], atol=1e-9)
            np.testing.assert_allclose(model[c[j + 1]], lab[c[j + 2]], atol=1e-9)
            np.testing.assert_allclose(model[c[j + 2]], -lab[c[j + 1]], atol=1e-9)
    vl = vertical_loads(walking5_loads, (-90.0, 0.0, 0.0))
    assert vl.numbers == (1, 2) and vl.vertical_n.shape == (8824, 2)
    np.testing.assert_allclose(vl.rest_vertical_n, [-14.2, -18.1], atol=0.1)
    assert vl.vertical_n[4100, 0] == pytest.approx(480.3877 + 14.2, abs=0.1)
    np.testing.assert_allclose(vl.corners_m[0, 0], [0.6646, 0.0, -0.37932], atol=1e-5)


def test_table_refuses_mixed_time_bases(walking5_loads):
    p = walking5_loads[0]
    q = plate_loads(2, p.time_s + 0.001, p.force_n, p.moment_nm, p.corners_m)
    with pytest.raises(LoperInputError, match="plate 2 is not on the time base of plate 1"):
        external_loads_table([p, q])


# --------------------------------------------------------------------------- the lab's up direction


def test_surface_normal_turns_along_the_labs_up_for_either_corner_order():
    """A Y-up lab (BTS): the floor plate's normal is +Y whichever way round its corners are listed."""
    c = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])  # in the plane y = 0
    for corners in (c, c[::-1]):
        np.testing.assert_array_equal(surface_normal(corners, up=(0.0, 1.0, 0.0)), [0.0, 1.0, 0.0])
        np.testing.assert_array_equal(surface_normal(corners, up=(0.0, 2.0, 0.0)), [0.0, 1.0, 0.0])  # normalised
    # the default up is lab +Z: the same plate is a wall there, refused with the numbers that tell why
    with pytest.raises(LoperInputError) as caught:
        surface_normal(c, "bts.c3d (force platform 2)")
    assert str(caught.value) == (
        "bts.c3d (force platform 2): the plate does not face up: surface normal [0.0, -1.0, 0.0] is 90.0 deg from "
        "the up direction [0.0, 0.0, 1.0] (at most 45 deg); the lab's up is the direction "
        "markers.lab_to_model_rotation_deg turns into the model's +Y: check that setting for this lab"
    )
    # 44 deg from up is accepted, 46 deg refused
    for tilt, ok in ((44.0, True), (46.0, False)):
        a = np.radians(tilt)
        tilted = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, np.cos(a), np.sin(a)], [0.0, np.cos(a), np.sin(a)]])
        if ok:
            np.testing.assert_allclose(surface_normal(tilted, up=(0, 0, 1)), [0.0, -np.sin(a), np.cos(a)], atol=1e-15)
        else:
            with pytest.raises(LoperInputError, match="is 46.0 deg from the up direction"):
                surface_normal(tilted, up=(0, 0, 1))
    for bad in ((0.0, 0.0, 0.0), (0.0, np.nan, 1.0), (1.0, 0.0)):
        with pytest.raises(LoperInputError, match=r"bts\.c3d: up must be 3 finite numbers"):
            surface_normal(c, "bts.c3d", up=bad)


def test_plate_loads_of_a_y_up_lab_are_the_z_up_ones_turned(walking5_loads):
    """walking5's plates carried into a Y-up lab ((x, y, z) -> (x, z, -y)) with up = +Y: the same resting level,
    loaded samples, vertical force, COP and free moment, turned; also with the corners listed the other way."""
    Q = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    for p in walking5_loads:
        raw_f, raw_m = p.force_n + p.rest_force_n, p.moment_nm + p.rest_moment_nm
        for corners in (p.corners_m @ Q.T, (p.corners_m @ Q.T)[::-1]):
            q = plate_loads(
                p.number, p.time_s, raw_f @ Q.T, raw_m @ Q.T, corners, threshold_n=THRESHOLD_N, up=(0.0, 1.0, 0.0)
            )
            np.testing.assert_array_equal(q.loaded, p.loaded)
            np.testing.assert_array_equal(q.up, [0.0, 1.0, 0.0])
            np.testing.assert_allclose(q.normal, [0.0, 1.0, 0.0], atol=1e-12)
            np.testing.assert_allclose(q.rest_force_n, p.rest_force_n @ Q.T, atol=1e-9)
            np.testing.assert_allclose(q.cop_m, p.cop_m @ Q.T, atol=1e-9)
            np.testing.assert_allclose(q.free_moment_nm, p.free_moment_nm, atol=1e-9)
        vl = vertical_loads([q], (0.0, 0.0, 0.0))
        np.testing.assert_allclose(vl.vertical_n[:, 0], p.force_n[:, 2], atol=1e-9)
        np.testing.assert_allclose(vl.rest_vertical_n, [p.rest_force_n[2]], atol=1e-9)
    # read as if Z were up, the Y-up plate is a wall
    p = walking5_loads[0]
    with pytest.raises(LoperInputError, match="does not face up"):
        plate_loads(1, p.time_s, p.force_n @ Q.T, p.moment_nm @ Q.T, p.corners_m @ Q.T, threshold_n=THRESHOLD_N)


def test_resting_level_along_up():
    F, M = _synthetic(noise=2.0)
    Q = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    rest_f, rest_m, unloaded = resting_level(F @ Q.T, M @ Q.T, band_n=10.0, up=(0.0, 1.0, 0.0))
    expected_f, expected_m, expected_unloaded = resting_level(F, M, band_n=10.0)
    np.testing.assert_array_equal(unloaded, expected_unloaded)
    np.testing.assert_allclose(rest_f, expected_f @ Q.T, atol=1e-12)
    np.testing.assert_allclose(rest_m, expected_m @ Q.T, atol=1e-12)
    loaded_f, loaded_m = _synthetic(n_rest=0, n_load=50)
    with pytest.raises(LoperInputError, match=r"resting vertical force 440\.0 N exceeds 100 N"):
        resting_level(loaded_f @ Q.T, loaded_m @ Q.T, up=(0.0, 1.0, 0.0))
