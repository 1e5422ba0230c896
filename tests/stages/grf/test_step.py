"""The grf step: walking5.c3d and a known point load to an external-loads .mot that OpenSim applies."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.grf import external_loads_columns, plate_vertical_loads
from loper_analysis.gait.grf_settings import GRFSettings
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.stages.grf.step import grf
from tests.io.force_plate_files import (
    channels_for_load,
    plate_corners_mm,
    write_plate_c3d,
)
from tests.io.test_force_platforms import WALKING5, reference_grfs


def _external_forces(xml_path, mot_path, bodies):
    """OpenSim's ExternalForce objects of ``xml_path`` on a model holding ``bodies``, fed from ``mot_path``."""
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    model = osim.Model()
    for name in bodies:
        body = osim.Body(name, 1.0, osim.Vec3(0), osim.Inertia(0.1, 0.1, 0.1))
        model.addBody(body)
        model.addJoint(osim.FreeJoint(f"free_{name}", model.getGround(), body))
    loads = osim.ExternalLoads(str(xml_path), True)
    storage = osim.Storage(str(mot_path))
    for i in range(loads.getSize()):
        force = loads.get(i).clone()
        force.setDataSource(storage)
        model.addForce(force)
    model.initSystem()
    forces = {}
    for i in range(loads.getSize()):
        name = loads.get(i).getName()
        forces[name] = osim.ExternalForce.safeDownCast(model.getForceSet().get(name))
    return model, storage, forces


def _vec(v) -> np.ndarray:
    return np.array([v.get(0), v.get(1), v.get(2)])


def test_walking5_mot_applied_by_opensim(tmp_path):
    out = tmp_path / "walking5.grf.mot"
    xml = tmp_path / "setup" / "walking5.grf.xml"
    table = grf(WALKING5, out, GRFSettings(rotation_deg=(0, 0, 0)), xml_out=xml, bodies={1: "calcn_r", 2: "calcn_l"})
    assert table.shape == (8824, 19) and out.is_file()
    head = out.read_text().splitlines()
    assert "inDegrees=no" in head and head[head.index("endheader") + 1].split("\t")[:2] == ["time", "1_ground_force_vx"]
    _, storage, forces = _external_forces(xml, out, ["calcn_r", "calcn_l"])
    assert storage.getSize() == 8824
    t, ref = reference_grfs()
    k = int(np.flatnonzero(np.isclose(t, 2.05))[0])
    row = table.iloc[4100]
    for n, body in ((1, "plate1"), (2, "plate2")):
        cols = external_loads_columns(n)
        ef = forces[body]
        np.testing.assert_allclose(_vec(ef.getForceAtTime(2.05)), row[cols[0:3]].to_numpy(dtype=float), atol=1e-9)
        np.testing.assert_allclose(_vec(ef.getPointAtTime(2.05)), row[cols[3:6]].to_numpy(dtype=float), atol=1e-12)
        np.testing.assert_allclose(_vec(ef.getTorqueAtTime(2.05)), row[cols[6:9]].to_numpy(dtype=float), atol=1e-12)
    # plate 1 in stance at 2.05 s: OpenSim's reading minus the resting level (-14.2 N vertical)
    f = _vec(forces["plate1"].getForceAtTime(2.05))
    assert f[2] == pytest.approx(ref[k, 0, 2] + 14.2064, abs=0.01)
    p = _vec(forces["plate1"].getPointAtTime(2.05))
    np.testing.assert_allclose(p, [1.11606, 0.458283, 0.0], atol=1e-5)
    # plate 2 not yet loaded at 2.05 s: zero force and torque
    np.testing.assert_array_equal(_vec(forces["plate2"].getForceAtTime(2.05)), 0.0)


def test_default_rotation_puts_vertical_on_y(tmp_path):
    table = grf(WALKING5, tmp_path / "w.grf.mot")
    lab = grf(WALKING5, tmp_path / "lab.grf.mot", GRFSettings(rotation_deg=(0, 0, 0)))
    np.testing.assert_allclose(table["1_ground_force_vy"], lab["1_ground_force_vz"], atol=1e-9)
    np.testing.assert_allclose(table["1_ground_force_pz"], -lab["1_ground_force_py"], atol=1e-9)
    # the peak is the raw channel's (Fz1 in the plate's downward z, so minus) above the -14.21 N resting level
    fz1 = read_c3d(WALKING5).analog("Fz1")
    assert table["1_ground_force_vy"].max() == pytest.approx(-fz1.min() + 14.2064, abs=1e-3)


def test_known_point_load_through_the_step(tmp_path):
    """TYPE 4 plate, resting offset then a load: the .mot holds the load, its point and its free moment."""
    centre = np.array([300.0, 200.0, 0.0])
    origin = (1.5, -2.0, 40.0)
    load, point, free = np.array([30.0, -20.0, 700.0]), np.array([380.0, 150.0, 0.0]), 1500.0
    cal = np.diag([2.0, 2.0, 4.0, 10.0, 10.0, 5.0])
    cal[1, 2] = 0.3
    offset = channels_for_load([0.5, -1.0, -40.0], centre, 0.0, centre, origin)  # an unloaded plate reading -40 N
    loaded = channels_for_load(load, point, free, centre, origin)
    ch = np.vstack([np.tile(offset, (60, 1)), np.tile(offset + loaded, (40, 1))])
    c3d = write_plate_c3d(
        tmp_path / "load.c3d", np.linalg.solve(cal, ch.T).T, plate_type=4, cal=cal, origin_mm=origin, units=["V"] * 6
    )
    table = grf(c3d, tmp_path / "load.grf.mot", GRFSettings(rotation_deg=(0, 0, 0)))
    cols = external_loads_columns(1)
    got = table[cols].to_numpy()
    np.testing.assert_allclose(got[60:, 0:3], np.tile(load, (40, 1)), atol=1e-3)
    np.testing.assert_allclose(got[60:, 3:6], np.tile(point / 1000.0, (40, 1)), atol=1e-7)
    np.testing.assert_allclose(got[60:, 6:9], np.tile([0.0, 0.0, 1.5], (40, 1)), atol=1e-5)
    np.testing.assert_array_equal(got[:60, [0, 1, 2, 6, 7, 8]], 0.0)
    np.testing.assert_allclose(got[:60, 3:6], np.tile(point / 1000.0, (60, 1)), atol=1e-7)  # held at the contact
    np.testing.assert_allclose(table["time_s"].to_numpy()[[0, -1]], [0.0, 99 / 1000.0], atol=1e-12)
    vl = plate_vertical_loads(read_force_platforms(c3d), rotation_deg=(0, 0, 0))
    assert vl.rest_vertical_n[0] == pytest.approx(-40.0, abs=1e-4)
    np.testing.assert_allclose(vl.vertical_n[[0, 99], 0], [0.0, 700.0], atol=1e-3)
    np.testing.assert_allclose(vl.corners_m[0], plate_corners_mm() / 1000.0, atol=1e-9)


def test_no_platforms_writes_nothing(tmp_path):
    c3d = write_plate_c3d(tmp_path / "none.c3d", np.zeros((10, 6)), used=0)
    out = tmp_path / "none.grf.mot"
    with pytest.raises(LoperInputError, match=r"none\.c3d: FORCE_PLATFORM:USED = 0"):
        grf(c3d, out)
    assert list(tmp_path.iterdir()) == [c3d]
