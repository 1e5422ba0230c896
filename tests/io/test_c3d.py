"""C3D files through ezc3d: the reader (io/c3d.py) and the writer (io/c3d_writer.py).

Every file is a real one written in tmp_path by our writer, by raw ezc3d in
a child process, or by hand, and sometimes damaged byte by byte.
"""

import struct
import subprocess
import sys

import ezc3d
import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording, read_c3d
from loper_analysis.io.c3d_writer import write_c3d, write_recording
from tests.io.marker_arrays import LABELS, N_FRAMES, POINT_HZ, as_stored, lab_markers

ANALOG_HZ = 1024.0
RATIO = 8


#: Raw ezc3d writer, run in a child process like write_c3d does: an in-process
#: ezc3d write would break OpenSim's std::vector arguments for later tests.
RAW_WRITER = """
import sys, numpy as np, ezc3d
d = np.load(sys.argv[1], allow_pickle=False)
c = ezc3d.c3d()
c["parameters"]["POINT"]["RATE"]["value"] = [float(d["rate"])]
c["parameters"]["POINT"]["LABELS"]["value"] = [str(v) for v in d["labels"]]
if len(d["units"]):
    c["parameters"]["POINT"]["UNITS"]["value"] = [str(v) for v in d["units"]]
if d["residuals"].size:
    r = d["residuals"]
    c["data"]["meta_points"] = {"residuals": r, "camera_masks": np.zeros((7, *r.shape[1:]), bool)}
c["data"]["points"] = d["points"]
if d["analogs"].size:
    c["parameters"]["ANALOG"]["RATE"]["value"] = [float(d["analog_rate"])]
    c["parameters"]["ANALOG"]["LABELS"]["value"] = [f"CH{k}" for k in range(d["analogs"].shape[1])]
    c["parameters"]["ANALOG"]["UNITS"]["value"] = ["V"] * d["analogs"].shape[1]
    c["data"]["analogs"] = d["analogs"]
c.write(sys.argv[2])
"""


def raw_c3d(path, labels, points, rate=POINT_HZ, units=("mm",), analogs=None, analog_rate=0.0, residuals=None):
    """A C3D written by raw ezc3d: points (4, n_markers, n_frames) in the file's unit; units None = not declared."""
    payload = path.with_name(path.name + ".npz")
    np.savez(
        payload,
        rate=rate,
        labels=np.array(labels, dtype=str),
        units=np.array(units or [], dtype=str),
        points=points,
        residuals=np.zeros(0) if residuals is None else residuals,
        analogs=np.zeros(0) if analogs is None else analogs,
        analog_rate=analog_rate,
    )
    subprocess.run([sys.executable, "-c", RAW_WRITER, str(payload), str(path)], check=True)
    payload.unlink()
    return path


def ones_points(values_xyz, n_markers=1, n_frames=4):
    p = np.ones((4, n_markers, n_frames))
    p[:3] = np.asarray(values_xyz, float)[:, None, None]
    return p


def data_offset(path) -> int:
    """Byte offset of the first frame (POINT:DATA_START is a 512-byte block number, 1-based)."""
    return (int(ezc3d.c3d(str(path))["parameters"]["POINT"]["DATA_START"]["value"][0]) - 1) * 512


def patch_parameter_float(path, old: float, new: float) -> None:
    """Replace the one float32 ``old`` of the parameter section (blocks 2 .. data start) by ``new``."""
    data = bytearray(path.read_bytes())
    start, stop = 512, data_offset(path)
    pattern = struct.pack("<f", old)
    hits = [i for i in range(start, stop - 3) if data[i : i + 4] == pattern]
    assert len(hits) == 1, hits
    data[hits[0] : hits[0] + 4] = struct.pack("<f", new)
    path.write_bytes(bytes(data))


# ---------------------------------------------------------------- round trips


@pytest.mark.parametrize("unit, units_per_m", [("mm", 1000.0), ("cm", 100.0), ("m", 1.0)])
def test_marker_round_trip_keeps_values_to_float32_and_gaps(tmp_path, rng, unit, units_per_m):
    X = lab_markers(rng)
    path = write_c3d(tmp_path / "trial.c3d", LABELS, X, POINT_HZ, point_unit=unit)
    rec = read_c3d(path)
    assert rec.marker_labels == LABELS
    assert rec.point_rate_hz == POINT_HZ
    assert rec.first_frame == 0
    assert rec.markers_m.shape == (N_FRAMES, 3, 3)
    np.testing.assert_array_equal(rec.markers_m, as_stored(X, units_per_m))  # NaN in the same places
    assert np.isnan(rec.markers_m).sum() == 3 * 3 + 3
    np.testing.assert_allclose(rec.time_s, np.arange(N_FRAMES) / 128.0, rtol=0, atol=0)
    assert rec.time_s[-1] == 39 / 128


def test_missing_point_is_stored_as_zero_with_residual_minus_one(tmp_path):
    X = np.full((3, 2, 3), 0.5)
    X[1, 1] = [np.nan, 0.2, 0.3]  # one NaN coordinate makes the whole point missing
    path = write_c3d(tmp_path / "gap.c3d", ["A", "B"], X, 100.0)
    words = np.frombuffer(path.read_bytes(), "<f4", count=3 * 2 * 4, offset=data_offset(path)).reshape(3, 2, 4)
    np.testing.assert_array_equal(words[1, 1], [0.0, 0.0, 0.0, -1.0])
    np.testing.assert_array_equal(words[1, 0], [500.0, 500.0, 500.0, 0.0])
    rec = read_c3d(path)
    assert np.isnan(rec.markers_m[1, 1]).all()
    assert rec.markers_m[1, 0, 0] == 0.5


def test_analog_round_trip_at_1024_hz_with_128_hz_points(tmp_path, rng):
    X = lab_markers(rng)
    A = np.column_stack(
        [
            rng.normal(0.0, 300.0, N_FRAMES * RATIO),  # a force in N
            np.sin(2 * np.pi * 5.0 * np.arange(N_FRAMES * RATIO) / ANALOG_HZ),  # a voltage
        ]
    )
    path = write_c3d(tmp_path / "a.c3d", LABELS, X, POINT_HZ, ["Force", "Sync"], A, ["N", "V"], ANALOG_HZ)
    rec = read_c3d(path)
    assert rec.analog_labels == ["Force", "Sync"]
    assert rec.analog_units == ["N", "V"]
    assert rec.analog_rate_hz == 1024.0
    assert rec.samples_per_frame == 8
    assert rec.analogs.shape == (320, 2)
    np.testing.assert_array_equal(rec.analogs, A.astype(np.float32).astype(np.float64))
    np.testing.assert_array_equal(rec.analog("Sync"), np.float32(A[:, 1]).astype(float))
    np.testing.assert_allclose(rec.analog_time_s[::8], rec.time_s, rtol=0, atol=1e-15)
    assert rec.analog_time_s[1] == 1 / 1024


def test_analog_lookup_of_an_absent_channel_names_file_and_channels(tmp_path, rng):
    A = np.zeros((N_FRAMES * RATIO, 2))
    path = write_c3d(
        tmp_path / "a.c3d", LABELS, lab_markers(rng), POINT_HZ, ["Force", "Sync"], A, ["N", "V"], ANALOG_HZ
    )
    with pytest.raises(LoperInputError) as err:
        read_c3d(path).analog("Torque")
    assert str(path) in str(err.value) and "'Torque'" in str(err.value) and "Force, Sync" in str(err.value)


def test_file_without_analogs_has_zero_channels(tmp_path, rng):
    path = write_c3d(tmp_path / "m.c3d", LABELS, lab_markers(rng), POINT_HZ)
    rec = read_c3d(path)
    assert rec.analogs.shape == (N_FRAMES, 0)
    assert rec.analog_labels == [] and rec.analog_rate_hz == POINT_HZ


@pytest.mark.parametrize("unit, expected_m", [("mm", 1.2345), ("cm", 12.345), ("m", 1234.5), ("MM", 1.2345)])
def test_point_units_are_converted_to_metres(tmp_path, unit, expected_m):
    path = raw_c3d(tmp_path / "u.c3d", ["A"], ones_points([1234.5, -1234.5, 0.5]), units=[unit])
    rec = read_c3d(path)
    np.testing.assert_allclose(rec.markers_m[0, 0], [expected_m, -expected_m, 0.5 * expected_m / 1234.5], rtol=1e-15)


def test_zero_points_and_negative_residuals_are_missing(tmp_path):
    pts = ones_points([10.0, 20.0, 30.0], n_markers=2, n_frames=4)
    pts[:3, 0, 1] = 0.0  # (0, 0, 0) with residual 0: a writer that ignores residuals
    path = raw_c3d(tmp_path / "z.c3d", ["A", "B"], pts)
    # Frame 2 of marker B: coordinates kept but residual -1 (ezc3d itself would zero them).
    data = bytearray(path.read_bytes())
    struct.pack_into("<f", data, data_offset(path) + (2 * 2 + 1) * 16 + 12, -1.0)
    path.write_bytes(bytes(data))
    rec = read_c3d(path)
    assert np.isnan(rec.markers_m[1, 0]).all()
    assert np.isnan(rec.markers_m[2, 1]).all()
    assert np.isnan(rec.markers_m).sum() == 6
    np.testing.assert_array_equal(rec.markers_m[3, 1], [0.01, 0.02, 0.03])


def test_first_frame_from_the_header_sets_the_times(tmp_path, rng):
    A = np.zeros((N_FRAMES * RATIO, 1))
    path = write_c3d(tmp_path / "f.c3d", LABELS, lab_markers(rng), POINT_HZ, ["Sync"], A, ["V"], ANALOG_HZ)
    data = bytearray(path.read_bytes())
    struct.pack_into("<HH", data, 6, 11, 11 + N_FRAMES - 1)  # header words 4, 5: first and last frame, 1-based
    path.write_bytes(bytes(data))
    rec = read_c3d(path)
    assert rec.first_frame == 10
    assert rec.time_s[0] == 10 / 128 and rec.time_s[-1] == 49 / 128
    assert rec.analog_time_s[0] == 10 / 128 and rec.analog_time_s[8] == 11 / 128


def test_more_than_255_labels_are_joined(tmp_path):
    labels = [f"M{k:03d}" for k in range(300)]
    X = np.arange(300 * 3, dtype=float).reshape(1, 300, 3) * 1e-3 + 1e-3
    path = write_c3d(tmp_path / "many.c3d", labels, np.repeat(X, 2, axis=0), 100.0)
    rec = read_c3d(path)
    assert rec.marker_labels == labels
    np.testing.assert_allclose(rec.markers_m[1, 299], [0.898, 0.899, 0.900], rtol=1e-7)


def test_same_inputs_give_identical_bytes(tmp_path, rng):
    X = lab_markers(rng)
    A = rng.normal(size=(N_FRAMES * RATIO, 2))
    args = (LABELS, X, POINT_HZ, ["F1", "F2"], A, ["N", "N"], ANALOG_HZ)
    (tmp_path / "other").mkdir()
    first = write_c3d(tmp_path / "a.c3d", *args).read_bytes()
    again = write_c3d(tmp_path / "a.c3d", *args).read_bytes()
    elsewhere = write_c3d(tmp_path / "other" / "b.c3d", *args).read_bytes()
    assert len(first) > 1024
    assert first == again == elsewhere
    # and a read -> write cycle reproduces the file
    rec = read_c3d(tmp_path / "a.c3d")
    rewritten = write_c3d(
        tmp_path / "c.c3d",
        rec.marker_labels,
        rec.markers_m,
        rec.point_rate_hz,
        rec.analog_labels,
        rec.analogs,
        rec.analog_units,
        rec.analog_rate_hz,
    ).read_bytes()
    assert rewritten == first


def test_write_recording_reproduces_the_file_it_was_read_from(tmp_path, rng):
    A = rng.normal(size=(N_FRAMES * RATIO, 2))
    first = write_c3d(tmp_path / "a.c3d", LABELS, lab_markers(rng), POINT_HZ, ["F1", "F2"], A, ["N", "V"], ANALOG_HZ)
    again = write_recording(tmp_path / "b.c3d", read_c3d(first))
    assert again.read_bytes() == first.read_bytes()


def test_writer_creates_a_missing_directory(tmp_path, rng):
    X = lab_markers(rng)
    path = write_c3d(tmp_path / "new" / "deeper" / "w.c3d", LABELS, X, POINT_HZ)
    np.testing.assert_array_equal(read_c3d(path).markers_m, as_stored(X, 1000.0))
    assert [p.name for p in path.parent.iterdir()] == ["w.c3d"]  # no staging file left


# ---------------------------------------------------------------- refusals of the reader


def test_missing_file_is_refused(tmp_path):
    path = tmp_path / "nope.c3d"
    with pytest.raises(LoperInputError, match="not found") as err:
        read_c3d(path)
    assert str(path) in str(err.value)


def test_text_file_named_c3d_is_refused(tmp_path):
    path = tmp_path / "notes.c3d"
    path.write_text("subject S01, trial walk01\n" * 40)
    with pytest.raises(LoperInputError, match="not a readable C3D file") as err:
        read_c3d(path)
    assert str(path) in str(err.value)


@pytest.mark.parametrize("where", ["header", "parameters", "data"])
def test_truncated_file_is_refused(tmp_path, rng, where):
    A = rng.normal(size=(N_FRAMES * RATIO, 2))
    good = write_c3d(tmp_path / "good.c3d", LABELS, lab_markers(rng), POINT_HZ, ["F1", "F2"], A, ["N", "N"], ANALOG_HZ)
    data = good.read_bytes()
    start = data_offset(good)
    frame_bytes = (4 * 3 + 2 * RATIO) * 4
    cut = {"header": 100, "parameters": (512 + start) // 2, "data": start + 10 * frame_bytes + 7}[where]
    bad = tmp_path / "cut.c3d"
    bad.write_bytes(data[:cut])
    with pytest.raises(LoperInputError) as err:
        read_c3d(bad)
    message = str(err.value)
    assert str(bad) in message
    assert ("truncated" in message) or ("not a readable C3D file" in message)
    if where == "data":
        assert f"declares {N_FRAMES} frames but only 10 could be read" in message


def test_file_without_point_units_is_refused(tmp_path):
    path = raw_c3d(tmp_path / "nounit.c3d", ["A"], ones_points([1.0, 2.0, 3.0]), units=None)
    with pytest.raises(LoperInputError, match="POINT:UNITS not declared") as err:
        read_c3d(path)
    assert str(path) in str(err.value)


def test_unknown_point_unit_is_refused(tmp_path):
    path = raw_c3d(tmp_path / "inch.c3d", ["A"], ones_points([1.0, 2.0, 3.0]), units=["in"])
    with pytest.raises(LoperInputError, match="unknown POINT:UNITS 'in'") as err:
        read_c3d(path)
    assert str(path) in str(err.value)


def test_non_integer_analog_point_rate_ratio_is_refused(tmp_path):
    # Raw ezc3d cannot write such a file: it silently lowers ANALOG:RATE to
    # point rate * floor(ratio) (1000 Hz at 128 Hz points becomes 896 Hz).
    analogs = np.zeros((1, 1, 4 * RATIO))
    path = raw_c3d(tmp_path / "rates.c3d", ["A"], ones_points([1.0, 2.0, 3.0]), analogs=analogs, analog_rate=ANALOG_HZ)
    patch_parameter_float(path, ANALOG_HZ, 1000.0)
    assert ezc3d.c3d(str(path))["parameters"]["ANALOG"]["RATE"]["value"][0] == 1000.0
    with pytest.raises(LoperInputError, match="mismatched analog/point rates") as err:
        read_c3d(path)
    assert str(path) in str(err.value) and "1000 Hz" in str(err.value) and "128 Hz" in str(err.value)


# ---------------------------------------------------------------- refusals of the writer


def test_writer_refuses_non_integer_rate_ratio_and_leaves_nothing(tmp_path, rng):
    with pytest.raises(LoperInputError, match="mismatched analog/point rates") as err:
        write_c3d(tmp_path / "w.c3d", LABELS, lab_markers(rng), POINT_HZ, ["F"], np.zeros((313, 1)), ["N"], 1000.0)
    assert "w.c3d" in str(err.value)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "change, match",
    [
        (dict(marker_labels=["RASI", "RASI", "RKNE"]), "duplicated: RASI"),
        (dict(marker_labels=["A" * 256, "B", "C"]), "at most 255 characters"),
        (dict(markers_m=np.zeros((N_FRAMES, 2, 3))), r"must name 2 item\(s\), got 3"),
        (dict(analogs=np.zeros((N_FRAMES * RATIO - 1, 1))), r"shape \(n_frames \* samples per frame = 320"),
        (dict(analog_units=[]), "one unit per channel"),
        (dict(point_unit="inch"), "point_unit must be one of mm, cm, m"),
        (dict(analogs=np.full((N_FRAMES * RATIO, 1), np.inf)), r"analogs\[0, 0\] = inf"),
    ],
)
def test_writer_refusals_keep_the_previous_file(tmp_path, rng, change, match):
    kwargs = dict(
        marker_labels=LABELS,
        markers_m=lab_markers(rng),
        point_rate_hz=POINT_HZ,
        analog_labels=["F"],
        analogs=np.ones((N_FRAMES * RATIO, 1)),
        analog_units=["N"],
        analog_rate_hz=ANALOG_HZ,
    )
    path = write_c3d(tmp_path / "t.c3d", **kwargs)
    before = path.read_bytes()
    with pytest.raises(LoperInputError, match=match) as err:
        write_c3d(path, **{**kwargs, **change})
    assert str(path) in str(err.value)
    assert path.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir()] == ["t.c3d"]


def test_failure_after_ezc3d_wrote_leaves_no_temporary_file(tmp_path, rng):
    target = tmp_path / "taken.c3d"
    target.mkdir()  # os.replace of a file onto a directory fails after ezc3d has written
    with pytest.raises(LoperInputError, match="cannot write C3D file") as err:
        write_c3d(target, LABELS, lab_markers(rng), POINT_HZ)
    assert str(target) in str(err.value)
    assert [p.name for p in tmp_path.iterdir()] == ["taken.c3d"]
    assert list(target.iterdir()) == []


def test_recording_checks_its_shapes():
    with pytest.raises(LoperInputError, match=r"n_markers=2"):
        C3DRecording("x.c3d", ["A", "B"], np.zeros((5, 3, 3)), 100.0)


# ---------------------------------------------------------------- ezc3d and OpenSim in one process


def test_c3d_io_leaves_opensim_vector_arguments_working(tmp_path, rng):
    from loper_analysis.motion.opensim_ik import (
        markers_table,  # passes opensim.StdVectorDouble/String objects
    )

    X = lab_markers(rng)
    read_c3d(write_c3d(tmp_path / "w.c3d", LABELS, X, POINT_HZ))
    table = markers_table(np.arange(4) / 100.0, np.full((4, 2, 3), 0.25), ["A", "B"])
    assert table.getNumRows() == 4 and list(table.getColumnLabels()) == ["A", "B"]


def test_write_c3d_works_after_opensim_used_its_vectors(tmp_path):
    from loper_analysis.io.osim import quiet_opensim

    osim = quiet_opensim()
    osim.TimeSeriesTable(
        osim.StdVectorDouble([0.0, 1.0]), osim.Matrix.createFromMat(np.ones((2, 1))), osim.StdVectorString(["a"])
    )
    rec = read_c3d(write_c3d(tmp_path / "after.c3d", ["A"], np.full((2, 1, 3), 0.125), 100.0))
    np.testing.assert_array_equal(rec.markers_m[1, 0], [0.125, 0.125, 0.125])
