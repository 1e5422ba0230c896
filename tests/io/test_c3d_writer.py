"""io/c3d_writer.py: markers and analog channels read back by ezc3d and by the project's reader; and C3D files as a
motion-capture system exports them (the extras): first frame, force platforms, per-channel SCALE/OFFSET and
events, read back by ezc3d (in a child process) and by OpenSim where it can."""

import hashlib
import json
import re
import subprocess
import sys

import ezc3d
import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d, write_recording
from tests.force_plate_channels import plate_channels, plate_load

RATE, RATIO = 100.0, 10

#: sha256 of the two files of :func:`default_files`, recorded with the writer before the keyword-only extras.
DEFAULT_HASHES = {
    "markers.c3d": "56cb9d8f2ba3046fd1b04d63e31c70ce13b37dd662e2f40370c761e9fefc8921",
    "analogs.c3d": "4b74dc270b63d544a7f3bea14b1948677b149b1f9b6b3721fce7531ecdb83801",
}

#: ezc3d's force-platform extraction in a process that never loads OpenSim; prints JSON.
EZC3D_PLATFORMS = """
import json, sys, ezc3d
c = ezc3d.c3d(sys.argv[1], extract_forceplat_data=True)
print(json.dumps([{k: p[k].tolist() for k in ("force", "moment", "center_of_pressure", "Tz", "origin")}
                  for p in c["data"]["platform"]]))
"""

# A TYPE 2 plate turned a quarter turn in the lab (plate x = lab -y) with its sensor origin off-centre,
# and a TYPE 4 plate (plate x = lab x, y = lab -y, z down) with a full calibration matrix.
PLATE_2 = ForcePlatform(
    2, [(0.6, 0.0, 0.0), (0.6, 0.4, 0.0), (0.0, 0.4, 0.0), (0.0, 0.0, 0.0)], (0.002, -0.003, -0.04), (1, 2, 3, 4, 5, 6)
)
CAL = np.diag([500.0, 500.0, 1000.0, 8e4, 8e4, 4e4]) + 7.0 * np.sin(np.arange(36.0)).reshape(6, 6)
PLATE_4 = ForcePlatform(
    4,
    [(1.2, 0.0, 0.0), (0.7, 0.0, 0.0), (0.7, 0.5, 0.0), (1.2, 0.5, 0.0)],
    (0.01, 0.02, -0.05),
    (8, 9, 10, 11, 12, 7),
    tuple(map(tuple, CAL)),
)


def default_files(folder):
    t = np.arange(40)[:, None, None] / 128.0
    X = np.broadcast_to(
        0.1 + 0.01 * t + 0.001 * np.arange(3)[None, :, None] + np.array([0.0, 0.5, 1.0]), (40, 3, 3)
    ).copy()
    X[5:8, 1] = np.nan
    k = np.arange(320)
    A = np.column_stack([100.0 * np.sin(k / 17.0), (k % 50 < 5).astype(float)])
    labels = ["RASI", "LASI", "RKNE"]
    return [
        write_c3d(folder / "markers.c3d", labels, X, 128.0),
        write_c3d(folder / "analogs.c3d", labels, X, 128.0, ["Fz_left", "sync"], A, ["N", "V"], 1024.0),
    ]


def test_files_without_extras_keep_their_bytes(tmp_path):
    for path in default_files(tmp_path):
        assert hashlib.sha256(path.read_bytes()).hexdigest() == DEFAULT_HASHES[path.name]


def known_loads(n):
    """Forces (n, 3) N, points of application (n, 3) m per plate and free moments (n,) N·m."""
    s = np.linspace(0.0, 1.0, n)
    force = np.column_stack([30.0 - 60.0 * s, -20.0 + 5.0 * s, 700.0 + 200.0 * np.sin(3 * s)])
    cop_2 = np.column_stack([0.1 + 0.4 * s, 0.35 - 0.2 * s, np.zeros(n)])
    cop_4 = np.column_stack([0.75 + 0.4 * s, 0.05 + 0.4 * s, np.zeros(n)])
    return force, cop_2, cop_4, 3.0 - 5.0 * s


def plate_file(path, first_frame=0):
    n_frames = 5
    force, cop_2, cop_4, free = known_loads(n_frames * RATIO)
    A = np.zeros((n_frames * RATIO, 12))
    A[:, :6] = plate_channels(PLATE_2, force, cop_2, free)
    A[:, [7, 8, 9, 10, 11, 6]] = plate_channels(PLATE_4, force, cop_4, free)
    X = np.full((n_frames, 1, 3), 0.3)
    units = ["N"] * 3 + ["Nmm"] * 3 + ["V"] * 6
    write_c3d(
        path,
        ["M"],
        X,
        RATE,
        [f"CH{k}" for k in range(1, 13)],
        A,
        units,
        RATE * RATIO,
        first_frame=first_frame,
        force_platforms=[PLATE_2, PLATE_4],
    )
    return force, (cop_2, cop_4), free


def test_type_2_and_type_4_plates_read_back_by_ezc3d(tmp_path):
    path = tmp_path / "plates.c3d"
    force, cops, free = plate_file(path)
    out = subprocess.run([sys.executable, "-c", EZC3D_PLATFORMS, str(path)], capture_output=True, text=True, check=True)
    plates = json.loads(out.stdout)
    assert len(plates) == 2
    for plate, cop in zip(plates, cops):
        np.testing.assert_allclose(np.array(plate["force"]).T, force, rtol=0, atol=1e-3)  # N
        np.testing.assert_allclose(np.array(plate["center_of_pressure"]).T, 1000.0 * cop, rtol=0, atol=0.01)  # mm
        np.testing.assert_allclose(np.array(plate["Tz"])[2], 1000.0 * free, rtol=0, atol=1.0)  # N·mm
    # ezc3d keeps ORIGIN as written: z negative, sensor origin -> surface centre
    np.testing.assert_allclose(plates[0]["origin"], [2.0, -3.0, -40.0], atol=1e-4)


def test_plate_load_inverts_plate_channels():
    force, cop_2, cop_4, free = known_loads(7)
    for plate, cop in ((PLATE_2, cop_2), (PLATE_4, cop_4)):
        load = plate_load(plate, plate_channels(plate, force, cop, free))
        np.testing.assert_allclose(load["force_n"], force, atol=1e-9)
        np.testing.assert_allclose(load["cop_m"], cop, atol=1e-12)
        np.testing.assert_allclose(load["free_moment_nm"], free, atol=1e-9)


def test_first_frame_sets_header_and_times(tmp_path):
    path = tmp_path / "late.c3d"
    plate_file(path, first_frame=1000)
    rec = read_c3d(path)
    assert rec.first_frame == 1000
    assert rec.time_s[0] == 1000 / RATE == 10.0
    assert rec.analog_time_s[0] == 10.0 and rec.analog_time_s[1] == 10.0 + 1 / (RATE * RATIO)
    first_word = int.from_bytes(path.read_bytes()[6:8], "little")
    assert first_word == 1001  # the header counts frames from 1


def test_scales_and_offsets_round_trip_exactly(tmp_path):
    rng = np.random.default_rng(5)
    stored = rng.uniform(-3000.0, 3000.0, (40, 3)).astype(np.float32)  # what the file holds
    stored[:, 1:] = np.round(stored[:, 1:])  # ADC counts where there is an offset (exact float32 differences)
    scales = np.array([10.0 / 32768.0, 0.37, 2.5])
    offsets = np.array([0, 2048, 7])
    physical = (stored.astype(float) - offsets) * scales.astype(np.float32)  # the file's SCALE is float32
    path = write_c3d(
        tmp_path / "s.c3d",
        ["M"],
        np.full((4, 1, 3), 0.2),
        RATE,
        ["A", "B", "C"],
        physical,
        ["V", "V", "N"],
        RATE * RATIO,
        analog_scales=scales,
        analog_offsets=offsets,
    )
    rec = read_c3d(path)
    np.testing.assert_array_equal(rec.analogs, physical)  # exact
    params = ezc3d.c3d(str(path))["parameters"]["ANALOG"]
    np.testing.assert_array_equal(params["OFFSET"]["value"], offsets)
    np.testing.assert_array_equal(params["SCALE"]["value"], scales.astype(np.float32))
    start = (int(ezc3d.c3d(str(path))["parameters"]["POINT"]["DATA_START"]["value"][0]) - 1) * 512
    words = np.frombuffer(path.read_bytes(), "<f4", offset=start).reshape(4, 4 + 3 * RATIO)[:, 4:]
    np.testing.assert_array_equal(words.reshape(-1, 3), stored)


def test_events_round_trip(tmp_path):
    events = [("Left", "Foot Strike", 10.0234375), ("Right", "Foot Off", 75.5), ("General", "Perturbation", 8.0)]
    path = write_c3d(tmp_path / "e.c3d", ["M"], np.full((4, 1, 3), 0.2), RATE, first_frame=800, events=events)
    ev = ezc3d.c3d(str(path))["parameters"]["EVENT"]
    assert int(ev["USED"]["value"][0]) == 3
    assert list(ev["CONTEXTS"]["value"]) == ["Left", "Right", "General"]
    assert list(ev["LABELS"]["value"]) == ["Foot Strike", "Foot Off", "Perturbation"]
    times = np.asarray(ev["TIMES"]["value"], dtype=float)
    assert times.shape == (2, 3)
    np.testing.assert_array_equal(times[0], [0.0, 1.0, 0.0])  # whole minutes
    np.testing.assert_allclose(60.0 * times[0] + times[1], [10.0234375, 75.5, 8.0], rtol=0, atol=1e-5)


@pytest.mark.parametrize(
    "extras, match",
    [
        (
            {"force_platforms": [{"TYPE": 3, "CORNERS": np.eye(4, 3), "ORIGIN": (0, 0, 0), "CHANNEL": range(1, 7)}]},
            "type must be one of",
        ),
        (
            {"force_platforms": [{"TYPE": 2, "CORNERS": np.eye(4, 3), "ORIGIN": (0, 0, 0), "CHANNEL": range(2, 8)}]},
            r"uses channel\(s\) \[7\]",
        ),
        (
            {"force_platforms": [{"TYPE": 4, "CORNERS": np.eye(4, 3), "ORIGIN": (0, 0, 0), "CHANNEL": range(1, 7)}]},
            "needs cal_matrix",
        ),
        ({"analog_offsets": [0, 0, 0, 0, 0, -4]}, r"analog_offsets must be an integer >= 0, got -4"),
        ({"analog_scales": [1, 1, 0, 1, 1, 1]}, "analog_scales must be 6 finite, non-zero"),
        ({"first_frame": 70000}, "first_frame must be at most 65534"),
        ({"events": [("Left", "", 1.0)]}, "non-empty label"),
    ],
)
def test_bad_extras_are_refused_and_leave_nothing(tmp_path, extras, match):
    path = tmp_path / "bad.c3d"
    with pytest.raises(LoperInputError, match=match):
        write_c3d(
            path,
            ["M"],
            np.full((4, 1, 3), 0.2),
            RATE,
            [f"C{k}" for k in range(6)],
            np.zeros((40, 6)),
            ["V"] * 6,
            RATE * RATIO,
            **extras,
        )
    assert list(tmp_path.iterdir()) == []


def test_platform_from_mapping_equals_dataclass():
    mapping = {
        "TYPE": 4,
        "CORNERS": PLATE_4.corners_m,
        "ORIGIN": PLATE_4.origin_m,
        "CHANNEL": PLATE_4.channels,
        "CAL_MATRIX": CAL,
    }
    assert ForcePlatform.from_mapping(mapping) == PLATE_4


# --------------------------------------------------------------------------- markers and analogs


def _markers(n_frames: int = 6) -> np.ndarray:
    """(n, 2, 3) m: known positions, marker 1 missing in frames 2-3."""
    k = np.arange(n_frames)[:, None, None]
    X = np.array([[0.1, 0.2, 0.9], [-0.35, 1.25, 0.05]])[None] + 0.01 * k * np.array([1.0, -2.0, 0.5])
    X[2:4, 1] = np.nan
    return X


def test_markers_and_analogs_read_back_by_ezc3d_in_the_file_units(tmp_path):
    X = _markers()
    A = np.column_stack([np.linspace(-500.0, 700.0, 24), 0.25 * np.arange(24)])
    path = write_c3d(tmp_path / "a.c3d", ["RASI", "LHEE"], X, 50.0, ["Fz_left", "sync"], A, ["N", "V"], 200.0)
    c = ezc3d.c3d(str(path))
    P, AN = c["parameters"]["POINT"], c["parameters"]["ANALOG"]
    assert list(P["LABELS"]["value"]) == ["RASI", "LHEE"] and list(P["UNITS"]["value"]) == ["mm"]
    assert float(P["RATE"]["value"][0]) == 50.0 and float(AN["RATE"]["value"][0]) == 200.0
    assert list(AN["LABELS"]["value"]) == ["Fz_left", "sync"] and list(AN["UNITS"]["value"]) == ["N", "V"]
    points = np.transpose(c["data"]["points"][:3], (2, 1, 0))  # (frames, markers, xyz)
    present = np.isfinite(X).all(axis=2)
    np.testing.assert_allclose(points[present], 1000.0 * X[present], rtol=2e-7)  # mm, float32
    assert np.isnan(points[~present]).all()  # residual -1: ezc3d reads the point as missing
    np.testing.assert_array_equal(c["data"]["meta_points"]["residuals"][0] < 0, ~present.T)
    np.testing.assert_allclose(c["data"]["analogs"][0].T, A, rtol=2e-7)


def test_metre_files_hold_the_values_as_given(tmp_path):
    X = _markers()
    path = write_c3d(tmp_path / "m.c3d", ["RASI", "LHEE"], X, 50.0, point_unit="m")
    c = ezc3d.c3d(str(path))
    assert list(c["parameters"]["POINT"]["UNITS"]["value"]) == ["m"]
    np.testing.assert_allclose(c["data"]["points"][:3, 0, :].T, X[:, 0], rtol=2e-7)
    np.testing.assert_allclose(read_c3d(path).markers_m, X, rtol=2e-7)


def test_write_recording_round_trips_a_read_file(tmp_path):
    X = _markers()
    A = np.column_stack([np.linspace(-5.0, 7.0, 12)])
    first = write_c3d(tmp_path / "1.c3d", ["RASI", "LHEE"], X, 50.0, ["Fz"], A, ["N"], 100.0, first_frame=7)
    rec = read_c3d(first)
    again = read_c3d(write_recording(tmp_path / "2.c3d", rec))
    assert (again.first_frame, again.marker_labels, again.analog_labels) == (7, ["RASI", "LHEE"], ["Fz"])
    np.testing.assert_allclose(again.time_s, (7 + np.arange(6)) / 50.0, rtol=1e-12)
    np.testing.assert_array_equal(again.markers_m, rec.markers_m)
    np.testing.assert_array_equal(again.analogs, rec.analogs)
    np.testing.assert_allclose(again.markers_m, X, rtol=2e-7)


@pytest.mark.parametrize(
    "labels, analog_rate_hz, analogs, message",
    [
        (["A", "A"], 100.0, np.zeros((12, 1)), "marker_labels duplicated: A"),
        (["A"], 100.0, np.zeros((12, 1)), "marker_labels must name 2 item(s), got 1"),
        (
            ["A", "B"],
            75.0,
            np.zeros((9, 1)),
            "mismatched analog/point rates: ANALOG:RATE = 75 Hz is not an integer multiple of POINT:RATE = 50 Hz "
            "(ratio 1.5)",
        ),
        (
            ["A", "B"],
            100.0,
            np.zeros((11, 1)),
            "analogs must have shape (n_frames * samples per frame = 12, n_channels = 1), got (11, 1)",
        ),
        (["A", "B"], 100.0, np.full((12, 1), np.nan), "analogs[0, 0] = nan is not finite in float32"),
    ],
)
def test_bad_markers_and_analogs_are_refused_and_leave_nothing(tmp_path, labels, analog_rate_hz, analogs, message):
    path = tmp_path / "bad.c3d"
    with pytest.raises(LoperInputError, match=re.escape(f"{path}: {message}")):
        write_c3d(path, labels, _markers(), 50.0, ["Fz"], analogs, ["N"], analog_rate_hz)
    assert list(tmp_path.iterdir()) == []
