"""Force platforms read with ezc3d: OpenSim's reading of walking5.c3d, and files built from known loads."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.force_platforms import (
    count_force_platforms,
    read_force_platforms,
)
from tests.io.force_plate_files import (
    R_PLATE_TO_LAB,
    channels_for_load,
    plate_corners_mm,
    type3_channels,
    write_plate_c3d,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "opensim-core"
WALKING5 = DATA / "walking5.c3d"


def reference_grfs() -> tuple[np.ndarray, np.ndarray]:
    """OpenSim's reading of walking5.c3d: times (90,) and values (90, 2 plates, 9) in N, mm, N·mm."""
    d = np.loadtxt(DATA / "std_walking5_grfs.sto", skiprows=6)
    return d[:, 0], d[:, 1:].reshape(-1, 2, 9)


@pytest.fixture(scope="module")
def walking5():
    return read_force_platforms(WALKING5)


def test_walking5_plates_and_time_base(walking5):
    assert [(p.number, p.type, p.channels) for p in walking5] == [
        (1, 2, (1, 2, 3, 4, 5, 6)),
        (2, 2, (7, 8, 9, 10, 11, 12)),
    ]
    p = walking5[0]
    assert p.analog_rate_hz == 2000.0
    assert p.force_n.shape == p.moment_nm.shape == (8824, 3)
    assert p.time_s[0] == 0.0 and p.time_s[-1] == pytest.approx(8823 / 2000.0, abs=1e-12)
    np.testing.assert_allclose(p.corners_m[:, 0], [0.6646, 0.6646, 1.1726, 1.1726], atol=1e-7)
    np.testing.assert_allclose(p.centre_m, [0.9186, 0.611095, 0.0], atol=1e-7)


def test_walking5_equals_opensims_reading(walking5):
    """Force (N), centre (mm) and moment about it (N·mm) of std_walking5_grfs.sto, every stored row, raw."""
    t, ref = reference_grfs()
    for p in walking5:
        idx = np.searchsorted(p.time_s, t - 1e-9)
        np.testing.assert_array_equal(np.round(p.time_s[idx], 9), np.round(t, 9))
        r = ref[:, p.number - 1]
        assert np.max(np.abs(p.force_n[idx] - r[:, 0:3])) < 0.05
        assert np.max(np.abs(p.centre_m * 1000.0 - r[:, 3:6])) < 1e-3
        assert np.max(np.abs(p.moment_nm[idx] - r[:, 6:9] / 1000.0)) < 0.05e-3  # N·m, i.e. 0.05 N·mm
    # the stance of plate 1 pushes up (ground reaction on the body): +480 N at 2.05 s
    assert walking5[0].force_n[4100, 2] == pytest.approx(480.3877, abs=1e-3)


LOAD_N = np.array([30.0, -20.0, 700.0])
POINT_MM = np.array([380.0, 150.0, 0.0])
FREE_NMM = 1500.0
CENTRE_MM = np.array([300.0, 200.0, 0.0])


def _expected_moment_nm(force_n=LOAD_N, point_mm=POINT_MM, free_nmm=FREE_NMM) -> np.ndarray:
    """Moment of the load about the surface centre, N·m, lab frame."""
    return (np.cross(point_mm - CENTRE_MM, force_n) + [0.0, 0.0, free_nmm]) / 1000.0


def test_type4_calibration_matrix_applied(tmp_path):
    origin = (1.5, -2.0, 40.0)
    cal = np.eye(6) * [2.0, 2.0, 4.0, 10.0, 10.0, 5.0]
    cal[0, 1], cal[2, 0], cal[4, 3] = 0.1, -0.05, 0.2  # not symmetric: the row/column order matters
    ch = channels_for_load(LOAD_N, POINT_MM, FREE_NMM, CENTRE_MM, origin)
    volts = np.linalg.solve(cal, ch)
    analogs = np.tile(volts, (20, 1))
    path = write_plate_c3d(
        tmp_path / "t4.c3d", analogs, plate_type=4, cal=cal, origin_mm=origin, units=["V"] * 6, ratio=10
    )
    (p,) = read_force_platforms(path)
    assert p.type == 4
    np.testing.assert_allclose(p.force_n[0], LOAD_N, atol=1e-3)
    np.testing.assert_allclose(p.moment_nm[0], _expected_moment_nm(), atol=1e-5)
    np.testing.assert_allclose(p.corners_m, plate_corners_mm() / 1000.0, atol=1e-9)


def test_type3_kistler_channels(tmp_path):
    a, b, depth = 210.0, 120.0, 45.0
    ch = type3_channels(LOAD_N, POINT_MM, FREE_NMM, CENTRE_MM, a, b, depth)
    path = write_plate_c3d(tmp_path / "t3.c3d", np.tile(ch, (20, 1)), plate_type=3, origin_mm=(a, b, -depth))
    (p,) = read_force_platforms(path)
    np.testing.assert_allclose(p.force_n[5], LOAD_N, atol=1e-3)
    np.testing.assert_allclose(p.moment_nm[5], _expected_moment_nm(), atol=1e-5)


def test_channels_by_number_not_label(tmp_path):
    """Voltage channels named like force channels (QTM) are ignored: CHANNEL points at 7..12."""
    ch = channels_for_load(LOAD_N, POINT_MM, FREE_NMM, CENTRE_MM, (0.0, 0.0, 40.0))
    decoys = np.full(6, 3.3)
    analogs = np.tile(np.r_[decoys, ch], (10, 1))
    labels = ["FP1_FX", "FP1_FY", "FP1_FZ", "FP1_MX", "FP1_MY", "FP1_MZ", "Fx1", "Fy1", "Fz1", "Mx1", "My1", "Mz1"]
    path = write_plate_c3d(
        tmp_path / "qtm.c3d",
        analogs,
        channel=list(range(7, 13)),
        labels=labels,
        units=["V"] * 6 + ["N"] * 3 + ["Nmm"] * 3,
    )
    (p,) = read_force_platforms(path)
    assert p.channels == (7, 8, 9, 10, 11, 12)
    np.testing.assert_allclose(p.force_n[0], LOAD_N, atol=1e-3)
    np.testing.assert_allclose(p.moment_nm[0], _expected_moment_nm(), atol=1e-5)
    assert R_PLATE_TO_LAB[2, 2] == -1.0  # the plate's z points down, as in gait labs


@pytest.mark.parametrize("kind", ["used0", "no_group"])
def test_no_platforms(tmp_path, kind):
    path = write_plate_c3d(tmp_path / f"{kind}.c3d", np.zeros((10, 6)), used=0, group=kind == "used0")
    assert count_force_platforms(path) == 0
    with pytest.raises(
        LoperInputError, match=r"FORCE_PLATFORM:USED (= 0|absent): the file holds no force platforms"
    ) as err:
        read_force_platforms(path)
    assert str(path) in str(err.value)


def test_channel_pointing_at_missing_analog(tmp_path):
    path = write_plate_c3d(tmp_path / "badch.c3d", np.zeros((10, 6)), channel=[1, 2, 3, 4, 5, 9])
    assert count_force_platforms(path) == 1
    with pytest.raises(LoperInputError) as err:
        read_force_platforms(path)
    msg = str(err.value)
    assert str(path) in msg and "FORCE_PLATFORM:CHANNEL" in msg and "[1, 2, 3, 4, 5, 9]" in msg and "[9]" in msg
    assert "6 analog channel(s)" in msg


def test_unknown_type(tmp_path):
    path = write_plate_c3d(tmp_path / "t5.c3d", np.zeros((10, 8)), plate_type=5, channel=list(range(1, 9)))
    with pytest.raises(
        LoperInputError, match=r"t5\.c3d: FORCE_PLATFORM:TYPE of platform 1 is 5; supported types are 2, 3, 4"
    ):
        read_force_platforms(path)


def test_moment_unit_disagreeing_with_point_units(tmp_path):
    path = write_plate_c3d(tmp_path / "units.c3d", np.zeros((10, 6)), point_units="m", units=["N"] * 3 + ["Nmm"] * 3)
    with pytest.raises(LoperInputError, match=r"ANALOG:UNITS of channel 4 .* is 'Nmm'"):
        read_force_platforms(path)


def test_missing_file(tmp_path):
    with pytest.raises(LoperInputError, match="C3D file not found"):
        read_force_platforms(tmp_path / "nope.c3d")
