"""Damaged C3D files that ezc3d reads without a complaint are refused by the reader with one message naming the
file, the C3D parameter and its value, and the steps write nothing; good files read as before.

1. ``POINT:SCALE`` of the wrong sign: float data declared as 16-bit integers (and integers declared as floats).
2. A singular ``FORCE_PLATFORM:CAL_MATRIX`` of a TYPE 4 plate (a zero ``Fz`` row reads every load as 0 N).
3. ``FORCE_PLATFORM:CORNERS`` listed in the other order than the frame of the plate's channels.

Every damaged file is written here by our writer (two plates under a walking load of known timing, heel markers
over them) and patched byte by byte in its parameter section; the good files are those of the repository.
"""

from __future__ import annotations

import math
import re
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.stages.events.step import EventSettings, events
from loper_analysis.stages.grf.step import grf
from loper_analysis.stages.markers.step import markers as markers_step
from tests.force_plate_channels import wrench_channels

ROOT = Path(__file__).resolve().parents[2]
WALKING5 = ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
R11 = ROOT / "examples" / "rajagopal2016" / "raw" / "R11"

RATE, RATIO = 100.0, 10
N_FRAMES = 300
#: Words per frame of the trial: 2 markers x 4 words, 12 channels x 10 samples.
WORDS = 4 * 2 + 12 * RATIO
#: Plate centres (m, Z-up lab, surface at z = 0) and half sizes; plate 1 takes the left foot, plate 2 the right.
CENTRES = (np.array([0.3, 0.25, 0.0]), np.array([0.3, 0.75, 0.0]))
HALF = np.array([0.25, 0.2, 0.0])
#: Contacts (start, end) s on each plate: a half sine of PEAK_N on top of the resting reading REST_N.
CONTACTS = (((0.3, 0.9), (1.5, 2.1)), ((0.8, 1.4), (2.0, 2.6)))
PEAK_N = 700.0
REST_N = np.array([1.0, -2.0, -30.0])
#: Calibration of a TYPE 4 plate: bridge volts -> N and N·mm, with crosstalk (row = output Fx .. Mz).
CAL = np.diag([500.0, 500.0, 1000.0, 8e4, 8e4, 4e4]) + 7.0 * np.sin(np.arange(36.0)).reshape(6, 6)
FEET = {"left": "LHEE", "right": "RHEE"}
ON_N = 50.0


# ---------------------------------------------------------------- files


def parameter_data(data: bytes, group: str, name: str) -> tuple[int, int, tuple[int, ...]]:
    """Byte offset, type (-1 char, 1 byte, 2 int16, 4 float32) and dimensions of GROUP:NAME's values in the
    parameter section of a little-endian C3D file."""
    pos = (data[0] - 1) * 512 + 4
    groups, params = {}, {}
    while True:
        n_chars, ident = struct.unpack_from("<bb", data, pos)
        if n_chars == 0:
            break
        label = bytes(data[pos + 2 : pos + 2 + abs(n_chars)]).decode().upper()
        at = pos + 2 + abs(n_chars)
        (step,) = struct.unpack_from("<h", data, at)
        if ident < 0:
            groups[label] = -ident
        else:
            kind, n_dims = struct.unpack_from("<bb", data, at + 2)
            params[(ident, label)] = (at + 4 + n_dims, kind, tuple(data[at + 4 : at + 4 + n_dims]))
        if step == 0:
            break
        pos = at + step
    return params[(groups[group], name)]


def patched(path: Path, out: Path, group: str, name: str, values: dict[int, float]) -> Path:
    """A copy of ``path`` whose float parameter GROUP:NAME has ``values`` {flat index (file order): value}."""
    data = bytearray(path.read_bytes())
    offset, kind, _ = parameter_data(data, group, name)
    assert kind == 4
    for index, value in values.items():
        struct.pack_into("<f", data, offset + 4 * index, value)
    out.write_bytes(bytes(data))
    return out


def plate_corners(centre: np.ndarray) -> np.ndarray:
    """Corners (4, 3) m in the usual C3D order: plate x = lab x, y = lab -y, z = lab -z (down)."""
    quadrants = np.array([[1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0]], dtype=float)
    return centre + (quadrants * HALF) @ np.diag([1.0, -1.0, -1.0]).T


def load_shape(plate: int, t: np.ndarray) -> np.ndarray:
    """The load on plate ``plate`` (0-based) at times ``t`` (s) as a fraction of its peak: half sines."""
    shape = np.zeros_like(t)
    for a, b in CONTACTS[plate]:
        s = np.clip((t - a) / (b - a), 0.0, 1.0)
        shape += np.where((t > a) & (t < b), np.sin(np.pi * s), 0.0)
    return shape


def write_trial(
    path: Path, kind: int = 2, order=(0, 1, 2, 3), channels_order=(0, 1, 2, 3), sign: float = 1.0, offset_n=0.0
) -> Path:
    """Two plates of TYPE ``kind`` under the walking load and the heels over them.

    The channels are those of plates whose corners are listed in ``channels_order``; the file lists them in
    ``order``. ``sign`` -1 writes the force on the plate instead of on the body; ``offset_n`` adds a constant
    vertical force (N, lab up) to the first plate's every sample (a plate not zeroed).
    """
    t = np.arange(N_FRAMES * RATIO) / (RATE * RATIO)
    tm = np.arange(N_FRAMES) / RATE
    heels = np.empty((N_FRAMES, 2, 3))
    plates, columns = [], []
    for k, centre in enumerate(CENTRES):
        chans = tuple(range(1 + 6 * k, 7 + 6 * k))
        cal = tuple(map(tuple, CAL)) if kind == 4 else None
        corners = plate_corners(centre)
        physical = ForcePlatform(kind, corners[list(channels_order)], (0.002, -0.003, -0.04), chans, cal)
        plates.append(ForcePlatform(kind, corners[list(order)], physical.origin_m, chans, cal))
        shape = load_shape(k, t)
        heels[:, k] = centre + np.array([0.0, -0.1, 0.4])
        for a, b in CONTACTS[k]:
            heels[(tm >= a - 0.1) & (tm <= b + 0.1), k, 2] = 0.05
        force = sign * (np.column_stack([20.0 * shape, -10.0 * shape, PEAK_N * shape]) + REST_N)
        if k == 0:
            force[:, 2] += offset_n
        columns.append(wrench_channels(physical, force, np.zeros_like(force)))
    labels = [f"{q}{k}" for k in (1, 2) for q in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    units = (["N"] * 3 + ["Nmm"] * 3) * 2 if kind == 2 else ["V"] * 12
    return write_c3d(
        path, ["LHEE", "RHEE"], heels, RATE, labels, np.hstack(columns), units, RATE * RATIO, force_platforms=plates
    )


def heel_strikes_s() -> list[float]:
    """Heel strikes of the trial: the first analog sample past ON_N above the resting level, in time order."""
    dt = 1.0 / (RATE * RATIO)
    times = [a + (b - a) / math.pi * math.asin(ON_N / PEAK_N) for plate in CONTACTS for a, b in plate]
    return sorted(round(math.ceil(x / dt) * dt, 6) for x in times)


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    d = tmp_path_factory.mktemp("c3d_guards")
    return {"type2": write_trial(d / "type2.c3d"), "type4": write_trial(d / "type4.c3d", kind=4)}


def run_events(path: Path, out: Path):
    return events(path, out, EventSettings(foot_markers=FEET, threshold_on_n=ON_N))


def assert_refused_and_nothing_written(step, path: Path, out: Path, *fragments: str) -> str:
    """``step(path, out)`` raises LoperInputError naming the file and every fragment; a new output is not
    created, an existing one keeps its bytes. Returns the message."""
    with pytest.raises(LoperInputError) as err:
        step(path, out)
    message = str(err.value)
    assert message.startswith(f"{path}: "), message
    for fragment in fragments:
        assert fragment in message, (fragment, message)
    assert not out.exists()
    out.write_bytes(b"previous output\n")
    with pytest.raises(LoperInputError):
        step(path, out)
    assert out.read_bytes() == b"previous output\n"
    return message


def test_good_trials_give_the_known_heel_strikes(good, tmp_path):
    expected = heel_strikes_s()
    assert expected == [0.314, 0.814, 1.514, 2.014]
    for name, path in good.items():
        table = run_events(path, tmp_path / f"{name}.events.tsv")
        strikes = table.loc[table["event"] == "heel_strike", "time_s"].round(6).tolist()
        assert strikes == expected, name
        assert len(table) == 8


# ---------------------------------------------------------------- 1. POINT:SCALE against the data block


def test_float_data_declared_as_integers_is_refused(good, tmp_path):
    path = good["type2"]
    data = path.read_bytes()
    offset, _, _ = parameter_data(data, "POINT", "SCALE")
    assert struct.unpack_from("<f", data, offset) == (-1.0,)  # float data, as written
    assert len(data) - 4 * 512 == N_FRAMES * WORDS * 4  # DATA_START = 5: exactly the float block
    bad = patched(path, tmp_path / "scale_sign.c3d", "POINT", "SCALE", {0: 1.0})
    expected = (
        "POINT:SCALE = 1 (positive) declares 16-bit integer data",
        f"{N_FRAMES} frames of {WORDS} words need "
        f"{N_FRAMES * WORDS * 2} bytes as 16-bit integers ({N_FRAMES * WORDS * 4} as 4-byte floats) after "
        f"POINT:DATA_START = 5 (byte 2048); the file holds {N_FRAMES * WORDS * 4} bytes there",
    )
    with pytest.raises(LoperInputError) as err:
        read_c3d(bad)
    assert str(err.value).startswith(f"{bad}: ") and all(e in str(err.value) for e in expected)
    assert_refused_and_nothing_written(run_events, bad, tmp_path / "events.tsv", *expected)
    assert_refused_and_nothing_written(markers_step, bad, tmp_path / "markers.trc", *expected)


def integer_copy(path: Path, out: Path, scale: float, n_markers: int, n_words: int, n_frames: int) -> Path:
    """``path`` (float data, ANALOG:SCALE 1) rewritten as 16-bit integer data with POINT:SCALE = ``scale``:
    coordinates / scale, residual words and analog values rounded, the block padded to 512 bytes."""
    data = bytearray(path.read_bytes())
    start = (data[16] | data[17] << 8) * 512 - 512  # header word 9: DATA_START
    block = np.frombuffer(bytes(data[start:]), "<f4", count=n_frames * n_words).reshape(n_frames, n_words)
    block = block.astype(float)
    points = block[:, : 4 * n_markers].reshape(n_frames, n_markers, 4)
    points[:, :, :3] /= scale
    body = np.round(block).astype("<i2").tobytes()
    offset, _, _ = parameter_data(data, "POINT", "SCALE")
    struct.pack_into("<f", data, offset, scale)
    struct.pack_into("<f", data, 12, scale)  # header words 7-8: the same scale
    out.write_bytes(bytes(data[:start]) + body + bytes(-len(body) % 512))
    return out


def test_integer_data_declared_as_floats_is_refused(tmp_path):
    rng = np.random.default_rng(3)
    X = 0.2 + 0.5 * rng.random((40, 3, 3))
    X[5, 1] = np.nan
    A = np.round(rng.normal(0.0, 300.0, (320, 2)))
    floats = write_c3d(tmp_path / "floats.c3d", ["A", "B", "C"], X, 100.0, ["F1", "F2"], A, ["N", "N"], 800.0)
    ints = integer_copy(floats, tmp_path / "ints.c3d", 0.1, 3, 4 * 3 + 2 * 8, 40)
    rec = read_c3d(ints)  # the good integer file: 0.1 mm steps, the gap kept, the counts exact
    assert np.nanmax(np.abs(rec.markers_m - X)) < 0.05e-3 and np.isnan(rec.markers_m).sum() == 3
    np.testing.assert_array_equal(rec.analogs, A)
    bad = patched(ints, tmp_path / "ints_as_floats.c3d", "POINT", "SCALE", {0: -0.1})
    expected = (
        "POINT:SCALE = -0.1 (negative) declares 4-byte float data",
        "40 frames of 28 words need 4480 bytes as 4-byte floats (2240 as 16-bit integers) after "
        "POINT:DATA_START = 4 (byte 1536); the file holds 2560 bytes there",
    )
    with pytest.raises(LoperInputError) as err:
        read_c3d(bad)
    assert str(err.value).startswith(f"{bad}: ") and all(e in str(err.value) for e in expected)
    assert_refused_and_nothing_written(markers_step, bad, tmp_path / "markers.trc", *expected)


@pytest.mark.parametrize("extra_blocks", [1, 2, 8])
def test_trailing_blocks_pass(good, tmp_path, extra_blocks):
    """Spare blocks after the data (zeros, or a block of other bytes) change nothing."""
    reference = read_c3d(good["type2"])
    for fill in (0, 0x5A):
        path = tmp_path / f"spare{fill}.c3d"
        path.write_bytes(good["type2"].read_bytes() + bytes([fill]) * (512 * extra_blocks))
        rec = read_c3d(path)
        np.testing.assert_array_equal(rec.markers_m, reference.markers_m)
        np.testing.assert_array_equal(rec.analogs, reference.analogs)


def test_zero_blocks_after_integer_data_are_padding_not_floats(tmp_path):
    """Integer data followed by zero blocks up to the size floats would need is read, not refused."""
    X = np.full((40, 3, 3), 0.25)
    floats = write_c3d(
        tmp_path / "floats.c3d", ["A", "B", "C"], X, 100.0, ["F1", "F2"], np.ones((320, 2)), ["N", "N"], 800.0
    )
    ints = integer_copy(floats, tmp_path / "ints.c3d", 0.1, 3, 4 * 3 + 2 * 8, 40)
    padded = tmp_path / "padded.c3d"
    padded.write_bytes(ints.read_bytes() + bytes(4 * 512))  # 2560 + 2048 bytes: the float size, 4480 .. 5120
    np.testing.assert_allclose(read_c3d(padded).markers_m, X, atol=0.05e-3)
    junk = tmp_path / "junk.c3d"
    junk.write_bytes(ints.read_bytes() + bytes([1]) * (4 * 512))
    with pytest.raises(LoperInputError, match=r"junk\.c3d: POINT:SCALE = 0\.1 \(positive\)"):
        read_c3d(junk)


# ---------------------------------------------------------------- 2. FORCE_PLATFORM:CAL_MATRIX


def cal_index(row: int, column: int, plate: int) -> int:
    """Flat index (file order, dimensions (6, 6, n)) of CAL_MATRIX[row, column, plate], 0-based."""
    return row + 6 * column + 36 * plate


@pytest.mark.parametrize("case", ["zero Fz row", "equal columns", "rank 5", "NaN"])
def test_unusable_calibration_matrix_is_refused(good, tmp_path, case):
    cal32 = CAL.astype(np.float32).astype(float)
    if case == "zero Fz row":  # plate 2's Fz reads 0 whatever the load: no contact, no event
        plate, values = 2, {cal_index(2, j, 1): 0.0 for j in range(6)}
        fragments = ["rank 5 of 6", "zero row(s) 3 (Fz)", "[0, 0, 0, 0, 0, 0]"]
    elif case == "equal columns":  # channel 2 read as channel 1
        plate, values = 1, {cal_index(i, 1, 0): cal32[i, 0] for i in range(6)}
        fragments = ["rank 5 of 6", "equal columns 1 and 2", f"[{cal32[0, 0]:.4g}, {cal32[0, 0]:.4g}, "]
    elif case == "rank 5":  # column 6 = column 1 + column 2: no zero row, no equal columns
        plate, values = 1, {cal_index(i, 5, 0): cal32[i, 0] + cal32[i, 1] for i in range(6)}
        fragments = ["rank 5 of 6 (condition number", f"{cal32[0, 0] + cal32[0, 1]:.4g}]"]
    else:
        plate, values = 2, {cal_index(3, 3, 1): float("nan")}
        fragments = ["non-finite entries at (row, column) [(4, 4)]", "nan"]
    bad = patched(good["type4"], tmp_path / "cal.c3d", "FORCE_PLATFORM", "CAL_MATRIX", values)
    head = f"FORCE_PLATFORM:CAL_MATRIX of platform {plate} (TYPE 4) is unusable: "
    with pytest.raises(LoperInputError) as err:
        read_force_platforms(bad)
    assert str(err.value).startswith(f"{bad}: {head}")
    assert all(f in str(err.value) for f in fragments), str(err.value)
    assert_refused_and_nothing_written(run_events, bad, tmp_path / "events.tsv", head, *fragments)
    assert_refused_and_nothing_written(grf, bad, tmp_path / "grf.mot", head, *fragments)


def test_calibration_matrix_of_a_type2_plate_is_not_applied_nor_checked(good, tmp_path):
    """ezc3d reads TYPE 2 channels as they are: a zero CAL_MATRIX (our writer stores the identity) changes nothing."""
    zero = patched(
        good["type2"], tmp_path / "zero_cal.c3d", "FORCE_PLATFORM", "CAL_MATRIX", {i: 0.0 for i in range(72)}
    )
    for a, b in zip(read_force_platforms(good["type2"]), read_force_platforms(zero)):
        np.testing.assert_array_equal(a.force_n, b.force_n)
    peak = read_force_platforms(zero)[0].force_n[:, 2].max()
    assert peak == pytest.approx(PEAK_N + REST_N[2], abs=0.01)  # 670 N at the top of the half sine


# ---------------------------------------------------------------- 3. FORCE_PLATFORM:CORNERS against the channels


@pytest.mark.parametrize("order", [(3, 2, 1, 0), (1, 0, 3, 2)], ids=["reversed", "pairs swapped"])
def test_corners_in_the_other_order_than_the_channels_are_refused_naming_the_corners(tmp_path, order):
    bad = write_trial(tmp_path / "corners.c3d", order=order)
    listed = [[float(f"{v:.6g}") for v in c] for c in 1000.0 * plate_corners(CENTRES[0])[list(order)]]
    fragments = (
        f"FORCE_PLATFORM:CORNERS of platform 1 = {listed} mm give a plate z axis [0.0, 0.0, 1.0]",
        "pointing up: the corners are listed the other way round the plate",
        "its vertical force (along up [0.0, 0.0, 1.0]) points down while loaded: ",
        f"N at the 1st percentile, at most {-REST_N[2]:.1f} N at the 99th",
    )
    with pytest.raises(LoperInputError) as err:
        read_force_platforms(bad)
    assert str(err.value).startswith(f"{bad}: ") and all(f in str(err.value) for f in fragments), str(err.value)
    low = float(re.search(r"loaded: (-?[0-9.]+) N at the 1st percentile", str(err.value)).group(1))
    vertical = -(PEAK_N * load_shape(0, np.arange(N_FRAMES * RATIO) / (RATE * RATIO)) + REST_N[2])  # flipped
    assert low == pytest.approx(np.percentile(vertical, 1.0), abs=0.06)  # about -669.4 N of a 670 N peak
    message = assert_refused_and_nothing_written(run_events, bad, tmp_path / "events.tsv", *fragments)
    assert "resting vertical force" not in message  # no longer blamed on the force's resting level
    assert_refused_and_nothing_written(grf, bad, tmp_path / "grf.mot", *fragments)


def test_force_on_the_plate_with_the_usual_corners_names_both_causes(tmp_path):
    bad = write_trial(tmp_path / "on_plate.c3d", sign=-1.0)
    assert_refused_and_nothing_written(
        run_events,
        bad,
        tmp_path / "events.tsv",
        "FORCE_PLATFORM:CORNERS of platform 1 = [[550.0, 50.0, 0.0], [50.0, 50.0, 0.0], [50.0, 450.0, 0.0], "
        "[550.0, 450.0, 0.0]] mm give a plate z axis [0.0, 0.0, -1.0]",
        "pointing down (the usual order)",
        "force on the plate instead of on the body",
        f"at most {-REST_N[2]:.1f} N at the 99th",
    )


def test_a_plate_not_zeroed_is_named_as_an_offset_not_as_its_corners(tmp_path):
    bad = write_trial(tmp_path / "offset.c3d", offset_n=-3000.0)
    message = assert_refused_and_nothing_written(
        run_events,
        bad,
        tmp_path / "events.tsv",
        "platform 1: its vertical force (along up [0.0, 0.0, 1.0]) never comes near zero",
        "an offset of about 30",
        "the plate not zeroed before the trial, or the ANALOG:OFFSET of its channels [1, 2, 3, 4, 5, 6]",
    )
    assert "FORCE_PLATFORM:CORNERS" not in message  # walking: the load comes and goes on top of the offset


@pytest.mark.parametrize("order", [(3, 2, 1, 0), (1, 0, 3, 2)], ids=["reversed", "pairs swapped"])
def test_corners_either_way_round_pass_when_the_channels_are_in_their_frame(good, tmp_path, order):
    path = write_trial(tmp_path / "other_way.c3d", order=order, channels_order=order)
    table = run_events(path, tmp_path / "events.tsv")
    assert table.loc[table["event"] == "heel_strike", "time_s"].round(6).tolist() == heel_strikes_s()
    for usual, other in zip(read_force_platforms(good["type2"]), read_force_platforms(path)):
        np.testing.assert_allclose(other.force_n, usual.force_n, atol=1e-3)


# ---------------------------------------------------------------- real files read as before


def test_repository_files_pass_with_their_known_forces():
    """Peak vertical force (N) of every plate, and walking5's stance value checked against OpenSim elsewhere."""
    known = {
        WALKING5: [774.8641, 910.5085],
        R11 / "static.c3d": [433.7946, 400.4258],
        R11 / "walk-nodevice.c3d": [937.3806, 925.0706, 935.2106],
    }
    for path, peaks in known.items():
        rec = read_c3d(path)
        plates = read_force_platforms(path)
        assert rec.n_force_platforms == len(plates) == len(peaks)
        np.testing.assert_allclose([p.force_n[:, 2].max() for p in plates], peaks, atol=1e-4)
    assert read_force_platforms(WALKING5)[0].force_n[4100, 2] == pytest.approx(480.3877, abs=1e-3)
    assert read_c3d(WALKING5).markers_m.shape == (1103, 40, 3)


#: An analog-only C3D (force plates exported without the trajectories), written by ezc3d in a child process.
ANALOG_ONLY = """
import sys
import ezc3d
import numpy as np

c = ezc3d.c3d()
c["parameters"]["POINT"]["RATE"]["value"] = [100.0]
c["parameters"]["POINT"]["LABELS"]["value"] = []
c["parameters"]["ANALOG"]["RATE"]["value"] = [1000.0]
c["parameters"]["ANALOG"]["LABELS"]["value"] = ["Fx1", "Fy1", "Fz1"]
c["data"]["points"] = np.zeros((4, 0, 100))
c["data"]["analogs"] = np.zeros((1, 3, 1000))
c.write(sys.argv[1])
"""


def test_an_analog_only_c3d_is_named_as_holding_no_markers(tmp_path):
    path = tmp_path / "plates-only.c3d"
    subprocess.run([sys.executable, "-c", ANALOG_ONLY, str(path)], check=True)
    rec = read_c3d(path)
    assert rec.marker_labels == [] and rec.analog_labels == ["Fx1", "Fy1", "Fz1"]
    message = assert_refused_and_nothing_written(
        lambda c3d, out: markers_step(c3d, out, tmp_path / "gaps.tsv"),
        path,
        tmp_path / "out.trc",
        "no markers (POINT:LABELS holds no marker trajectory)",
        "3 analog channel(s) (Fx1, Fy1, Fz1)",
        "export the trial with its marker trajectories",
    )
    assert "shape" not in message
