"""OpenSim's text formats through OpenSim's adapters (io/opensim_tables.py): TRC markers and MOT coordinates.

Every file is a real one written in tmp_path by our writers or by hand;
OpenSim's own parser is the peer engine of the fast TRC reader.
"""

import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import (
    read_markers,
    read_mot,
    write_mot,
    write_trc,
)
from loper_analysis.io.osim import quiet_opensim
from tests.io.marker_arrays import LABELS, N_FRAMES, POINT_HZ, as_stored, lab_markers

# ---------------------------------------------------------------- TRC (OpenSim TRCFileAdapter)


@pytest.mark.parametrize("unit, scale", [("mm", 1000.0), ("m", 1.0)])
def test_trc_round_trip_through_opensim(tmp_path, rng, unit, scale):
    t = 2.0 + np.arange(N_FRAMES) / POINT_HZ
    X = lab_markers(rng)
    path = write_trc(tmp_path / "walk.trc", t, X, LABELS, unit=unit)
    lines = path.read_text().splitlines()
    assert lines[0].split("\t") == ["PathFileType", "4", "(X/Y/Z)", "walk.trc"]
    meta = dict(zip(lines[1].split("\t"), lines[2].split("\t")))
    assert meta["DataRate"] == "128" and meta["CameraRate"] == "128" and meta["Units"] == unit
    assert meta["NumFrames"] == "40" and meta["NumMarkers"] == "3"
    time_s, markers_m, labels = read_markers(path)
    assert labels == LABELS
    np.testing.assert_array_equal(time_s, t)
    assert np.array_equal(np.isnan(markers_m), np.isnan(X))
    np.testing.assert_allclose(markers_m, X, rtol=2e-15, atol=0)  # OpenSim prints 16 significant digits
    first = float(lines[6].split("\t")[2])
    assert first == pytest.approx(X[0, 0, 0] * scale, rel=1e-15)


@pytest.mark.parametrize("unit", ["mm", "m"])
def test_fast_trc_reader_equals_opensims_parser(tmp_path, rng, unit):
    t = np.arange(N_FRAMES) / POINT_HZ
    X = lab_markers(rng)  # with NaN gaps
    path = write_trc(tmp_path / "walk.trc", t, X, LABELS, unit=unit)
    fast_t, fast_X, fast_labels = read_markers(path)  # our layout: the fast text reader
    osim = quiet_opensim()
    table = osim.TimeSeriesTableVec3(str(path))
    flat_table = table.flatten(["_x", "_y", "_z"])
    matrix = flat_table.getMatrix()
    ref = np.array(matrix.to_numpy()).reshape(fast_X.shape) / {"mm": 1000.0, "m": 1.0}[unit]
    assert fast_labels == list(table.getColumnLabels())
    np.testing.assert_array_equal(fast_t, np.array(table.getIndependentColumn()))
    np.testing.assert_array_equal(fast_X, ref)  # bit for bit, NaN where OpenSim has NaN
    # a layout the fast reader does not know goes to OpenSim's parser, whose refusal names the file
    other = tmp_path / "other.trc"
    other.write_text(path.read_text().replace("PathFileType", "PathFileTypo", 1))
    with pytest.raises(LoperInputError, match="other.trc: OpenSim cannot read this TRC file"):
        read_markers(other)


def test_trc_with_one_marker_round_trips(tmp_path, rng):
    # OpenSim 4.6's packVec3 refuses a single marker; the writer works around it.
    t = np.arange(5) / 100.0
    X = rng.normal(size=(5, 1, 3))
    time_s, markers_m, labels = read_markers(write_trc(tmp_path / "one.trc", t, X, ["LBRA_P"], unit="m"))
    assert labels == ["LBRA_P"]
    np.testing.assert_allclose(markers_m, X, rtol=2e-15)


def _opensim_trc_bytes(path, t, X, labels, unit):
    """The same markers written by OpenSim's own TRCFileAdapter (the peer of our writer)."""
    osim = quiet_opensim()
    pad = [] if len(labels) > 1 else ["PAD"]  # OpenSim 4.6's packVec3 refuses a single marker
    flat = np.hstack([X.reshape(t.size, -1), np.zeros((t.size, 3 * len(pad)))])
    cols = [f"{lab}_{a}" for lab in [*labels, *pad] for a in "xyz"]
    table = osim.TimeSeriesTable(t.tolist(), osim.Matrix.createFromMat(flat), cols).packVec3(["_x", "_y", "_z"])
    for name in pad:
        table.removeColumn(name)
    rate = f"{1.0 / np.mean(np.diff(t)):.12g}"
    table.addTableMetaDataString("DataRate", rate)
    table.addTableMetaDataString("CameraRate", rate)
    table.addTableMetaDataString("Units", unit)
    osim.TRCFileAdapter().write(table, str(path))
    return path.read_bytes()


@pytest.mark.parametrize(
    "rate_hz, first, n_markers, scale, unit",
    [
        (128.0, 0, 36, 1.0, "mm"),
        (100.0, 7, 5, 1e-3, "m"),
        (120.0, 0, 1, 1e3, "cm"),
        (200.0, 3, 4, 1e-7, "mm"),
    ],
)
def test_trc_writer_writes_the_bytes_of_opensims_adapter(tmp_path, rng, rate_hz, first, n_markers, scale, unit):
    t = (first + np.arange(400)) / rate_hz
    X = scale * rng.normal(size=(t.size, n_markers, 3))
    X[5, 0, :] = np.nan  # a missing marker
    X[9, -1, 1] = -0.0
    labels = [f"M{i}" for i in range(n_markers)]
    (tmp_path / "osim").mkdir()
    ours = write_trc(tmp_path / "m.trc", t, X, labels, unit=unit).read_bytes()
    theirs = _opensim_trc_bytes(
        tmp_path / "osim" / "m.trc", t, X * {"mm": 1e3, "cm": 1e2, "m": 1.0}[unit], labels, unit
    )
    theirs = theirs.replace(str(tmp_path / "osim" / "m.trc").encode(), b"m.trc", 1)  # OpenSim prints its path
    assert ours == theirs


def test_trc_writer_is_deterministic_across_directories(tmp_path, rng):
    t = np.arange(N_FRAMES) / POINT_HZ
    X = lab_markers(rng)
    (tmp_path / "sub").mkdir()
    a = write_trc(tmp_path / "x.trc", t, X, LABELS).read_bytes()
    b = write_trc(tmp_path / "sub" / "x.trc", t, X, LABELS).read_bytes()
    assert a == b


def test_trc_with_unknown_units_is_refused(tmp_path, rng):
    path = write_trc(tmp_path / "u.trc", np.arange(4) / 100.0, rng.normal(size=(4, 1, 3)), ["A"])
    path.write_text(path.read_text().replace("\t4\t1\tmm\t", "\t4\t1\tin\t", 1))
    with pytest.raises(LoperInputError, match="unknown TRC Units 'in'") as err:
        read_markers(path)
    assert str(path) in str(err.value)


def test_trc_writer_refuses_unequal_steps(tmp_path):
    t = np.array([0.0, 0.01, 0.02, 0.035])
    with pytest.raises(LoperInputError, match="equally spaced") as err:
        write_trc(tmp_path / "s.trc", t, np.zeros((4, 1, 3)), ["A"])
    assert "s.trc" in str(err.value)
    assert list(tmp_path.iterdir()) == []


def test_trc_writer_creates_a_missing_directory(tmp_path, rng):
    t = np.arange(N_FRAMES) / POINT_HZ
    X = lab_markers(rng)
    path = write_trc(tmp_path / "new" / "x.trc", t, X, LABELS, unit="m")
    np.testing.assert_allclose(read_markers(path)[1], X, rtol=2e-15, atol=0)
    assert [p.name for p in path.parent.iterdir()] == ["x.trc"]  # no staging file left


def test_read_markers_of_a_c3d_matches_read_c3d(tmp_path, rng):
    X = lab_markers(rng)
    path = write_c3d(tmp_path / "w.c3d", LABELS, X, POINT_HZ)
    time_s, markers_m, labels = read_markers(path)
    assert labels == LABELS
    np.testing.assert_array_equal(markers_m, as_stored(X, 1000.0))
    assert time_s[5] == 5 / 128


def test_read_markers_refuses_unknown_suffix(tmp_path):
    with pytest.raises(LoperInputError, match=r"unknown marker file type '\.csv'"):
        read_markers(tmp_path / "m.csv")


# ---------------------------------------------------------------- MOT (OpenSim STOFileAdapter)


def coordinate_frame(rng, n=25):
    return pd.DataFrame(
        {
            "time_s": 1.0 + np.arange(n) / 100.0,
            "pelvis_tilt": rng.normal(0.0, 0.1, n),
            "pelvis_tx": rng.normal(1.0, 0.5, n),
            "pelvis_ty": rng.normal(0.9, 0.01, n),
            "knee_flexion_l": rng.uniform(0.0, 1.2, n),
        }
    )


@pytest.mark.parametrize("in_degrees, flag", [(True, "yes"), (False, "no")])
def test_mot_round_trip_honours_in_degrees(tmp_path, rng, in_degrees, flag):
    frame = coordinate_frame(rng)
    path = write_mot(tmp_path / "ik.mot", frame, in_degrees=in_degrees)
    text = path.read_text().splitlines()
    assert text[0] == "Coordinates" and f"inDegrees={flag}" in text
    columns = text.index("endheader") + 1
    assert text[columns].split("\t") == ["time", "pelvis_tilt", "pelvis_tx", "pelvis_ty", "knee_flexion_l"]
    row0 = [float(v) for v in text[columns + 1].split("\t")]
    factor = 180.0 / np.pi if in_degrees else 1.0
    assert row0[1] == pytest.approx(frame.pelvis_tilt[0] * factor, rel=1e-15)  # angle printed in the file's unit
    assert row0[2] == pytest.approx(frame.pelvis_tx[0], rel=1e-15)  # translation never converted
    back = read_mot(path)
    assert list(back.columns) == list(frame.columns)
    pd.testing.assert_frame_equal(back, frame, check_exact=False, rtol=1e-14, atol=0)


def test_read_mot_of_an_opensim_3_style_file_in_degrees(tmp_path):
    path = tmp_path / "old.mot"
    path.write_text(
        "Coordinates\nversion=1\nnRows=2\nnColumns=3\ninDegrees=yes\nendheader\n"
        "time\thip_flexion_r\tpelvis_tx\n0\t90\t0.5\n0.01\t-45\t0.25\n"
    )
    back = read_mot(path)
    np.testing.assert_allclose(back["hip_flexion_r"], [np.pi / 2, -np.pi / 4], rtol=1e-15)
    np.testing.assert_array_equal(back["pelvis_tx"], [0.5, 0.25])
    np.testing.assert_array_equal(back["time_s"], [0.0, 0.01])


def test_mot_without_in_degrees_is_refused(tmp_path):
    path = tmp_path / "nodeg.mot"
    path.write_text("Coordinates\nversion=1\nnRows=1\nnColumns=2\nendheader\ntime\tknee\n0\t10\n")
    with pytest.raises(LoperInputError, match="does not declare inDegrees") as err:
        read_mot(path)
    assert str(path) in str(err.value)


def test_write_mot_refuses_a_frame_without_time(tmp_path):
    with pytest.raises(LoperInputError, match="'time_s' column"):
        write_mot(tmp_path / "x.mot", pd.DataFrame({"knee": [0.1]}))
    assert list(tmp_path.iterdir()) == []


def test_mot_writer_creates_a_missing_directory(tmp_path, rng):
    frame = coordinate_frame(rng)
    path = write_mot(tmp_path / "new" / "ik.mot", frame, in_degrees=False)
    pd.testing.assert_frame_equal(read_mot(path), frame, check_exact=False, rtol=1e-14, atol=0)
    assert [p.name for p in path.parent.iterdir()] == ["ik.mot"]  # no staging file left


# ---------------------------------------------------------------- OpenSim tables after ezc3d in one process


AFTER_RAW_EZC3D = """
import sys, numpy as np, pandas as pd, ezc3d
from pathlib import Path
from loper_analysis.io.opensim_tables import read_markers, read_mot, write_mot, write_trc
out = Path(sys.argv[1])
c = ezc3d.c3d()  # an in-process ezc3d write takes over SWIG's std::vector converters
c["parameters"]["POINT"]["RATE"]["value"] = [100.0]
c["parameters"]["POINT"]["UNITS"]["value"] = ["mm"]
c["parameters"]["POINT"]["LABELS"]["value"] = ["A"]
c["data"]["points"] = np.ones((4, 1, 3))
c.write(str(out / "raw.c3d"))
t, X, labels = read_markers(write_trc(out / "m.trc", [0.0, 0.01], np.full((2, 1, 3), 0.5), ["A"], unit="m"))
frame = read_mot(write_mot(out / "c.mot", pd.DataFrame({"time_s": [0.0, 0.01], "knee": [0.5, 0.25]})))
print(labels[0], X[1, 0, 2], frame["knee"].iloc[1])
"""


def test_opensim_tables_work_after_an_in_process_ezc3d_write(tmp_path):
    # in a child process: the in-process ezc3d write must not leak into this test session
    proc = subprocess.run([sys.executable, "-c", AFTER_RAW_EZC3D, str(tmp_path)], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.split() == ["A", "0.5", "0.25"]


# ---------------------------------------------------------------- TRC labels with inner spaces (BTS)

SPACED = ["r heel", "l heel", "r  toe tip"]  # a double space stays as it is


def test_trc_labels_with_inner_spaces_are_opensims_bytes_and_read_back(tmp_path, rng):
    """Our writer's bytes equal OpenSim's adapter's for labels with spaces; our fast reader, OpenSim's
    TimeSeriesTableVec3 and TRCFileAdapter.read give back the same labels and the same numbers."""
    t = np.arange(N_FRAMES) / POINT_HZ
    X = lab_markers(rng)
    (tmp_path / "osim").mkdir()
    ours = write_trc(tmp_path / "bts.trc", t, X, SPACED, unit="mm")
    theirs = _opensim_trc_bytes(tmp_path / "osim" / "bts.trc", t, X * 1e3, SPACED, "mm")
    assert ours.read_bytes() == theirs.replace(str(tmp_path / "osim" / "bts.trc").encode(), b"bts.trc", 1)
    assert ours.read_text().splitlines()[3] == "Frame#\tTime\tr heel\t\t\tl heel\t\t\tr  toe tip\t\t\t"
    fast_t, fast_X, fast_labels = read_markers(ours)
    assert fast_labels == SPACED
    osim = quiet_opensim()
    table = osim.TimeSeriesTableVec3(str(ours))
    assert list(table.getColumnLabels()) == SPACED
    assert list(osim.TRCFileAdapter().read(str(ours))["markers"].getColumnLabels()) == SPACED
    flat_table = table.flatten(["_x", "_y", "_z"])
    matrix = flat_table.getMatrix()
    np.testing.assert_array_equal(fast_X, np.array(matrix.to_numpy()).reshape(fast_X.shape) / 1000.0)
    np.testing.assert_allclose(fast_X, X, rtol=2e-15, atol=0)
    np.testing.assert_array_equal(fast_t, t)


@pytest.mark.parametrize("label", ["r\theel", " r heel", "r heel ", "r\nheel"])
def test_trc_labels_that_would_not_read_back_are_refused(tmp_path, rng, label):
    """A tab or line break breaks the layout, and OpenSim strips edge blanks: refused, naming file and label."""
    path = tmp_path / "bad.trc"
    with pytest.raises(LoperInputError) as caught:
        write_trc(path, np.arange(N_FRAMES) / POINT_HZ, lab_markers(rng), ["RASI", label, "RKNE"])
    assert str(caught.value) == (
        f"{path}: labels must be non-empty strings without leading/trailing blanks or "
        f"whitespace other than inner spaces, got {label!r}"
    )
    assert not path.exists()


def test_fast_trc_reader_strips_edge_blanks_of_labels_as_opensim_does(tmp_path, rng):
    """A TRC written elsewhere with padded labels: both readers give the stripped labels."""
    path = write_trc(tmp_path / "padded.trc", np.arange(N_FRAMES) / POINT_HZ, lab_markers(rng), SPACED)
    lines = path.read_text().splitlines()
    lines[3] = "Frame#\tTime\t r heel \t\t\tl heel\t\t\tr  toe tip  \t\t\t"
    padded = tmp_path / "padded_by_hand.trc"
    padded.write_text("\n".join(lines) + "\n")
    assert read_markers(padded)[2] == SPACED
    assert list(quiet_opensim().TimeSeriesTableVec3(str(padded)).getColumnLabels()) == SPACED
