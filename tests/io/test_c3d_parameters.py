"""C3D parameters of real-world files: text that is not UTF-8, events in both layouts, the file's time base.

Files are written by our writer and patched byte by byte, or given events by
raw ezc3d in a child process (an in-process ezc3d write would break OpenSim's
std::vector arguments for later tests).
"""

import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_parameters import EVENT_COLUMNS, decode_text
from loper_analysis.io.c3d_writer import write_c3d

RATE_HZ = 100.0
N = 20


@pytest.fixture
def written(tmp_path):
    """A C3D with markers LASX, RASI and analog units N, mm/sX (X: a byte to patch)."""
    X = np.random.default_rng(3).uniform(-1, 1, size=(N, 2, 3))
    path = tmp_path / "plain.c3d"
    write_c3d(path, ["LASX", "RASI"], X, RATE_HZ, ["Fz", "Acc"], np.zeros((2 * N, 2)), ["N", "mm/sX"], 2 * RATE_HZ)
    return path


def _patch(path, out, *pairs):
    data = path.read_bytes()
    for old, new in pairs:
        assert data.count(old) == 1, old
        data = data.replace(old, new)
    out.write_bytes(data)
    return out


def test_latin1_unit_and_label_are_read_as_latin1(written, tmp_path):
    # 0xB2 is '²' and 0xC9 'É' in Latin-1; neither byte can start a UTF-8 character
    path = _patch(written, tmp_path / "latin1.c3d", (b"mm/sX", b"mm/s\xb2"), (b"LASX", b"LAS\xc9"))
    rec = read_c3d(path)
    assert rec.analog_units == ["N", "mm/s²"]
    assert rec.marker_labels == ["LASÉ", "RASI"]
    assert rec.marker_labels[0].encode("utf-8") == b"LAS\xc3\x89"  # a plain str again: encodable


def test_utf8_unit_stays_utf8(written, tmp_path):
    # '²' in UTF-8 is two bytes: the unit field of 5 characters now holds 6 bytes, so patch a 4-byte field instead
    path = _patch(written, tmp_path / "utf8.c3d", (b"LASX", b"L\xc2\xb2X"))
    assert read_c3d(path).marker_labels == ["L²X", "RASI"]


@pytest.mark.parametrize(
    "value, text",
    [
        ("mm/s\udcb2", "mm/s²"),
        (b"mm/s\xb2", "mm/s²"),
        ("Kraft ²", "Kraft ²"),
        (b" N\xc2\xb7m ", "N·m"),
    ],
)
def test_decode_text(value, text):
    assert decode_text(value) == text


#: Adds events to an existing C3D: argv = in, out, layout ("2xn" or "flat").
EVENT_WRITER = """
import sys, numpy as np, ezc3d
c = ezc3d.c3d(sys.argv[1])
times = np.array([[0.0, 0.0, 1.0], [0.05, 0.12, 0.5]])  # minutes, seconds
c.add_parameter("EVENT", "USED", [3])
c.add_parameter("EVENT", "CONTEXTS", ["Left", "Right", "Left"])
c.add_parameter("EVENT", "LABELS", ["Foot Strike", "Foot Off", "Foot Off"])
c.add_parameter("EVENT", "TIMES", times if sys.argv[3] == "2xn" else times.T.ravel().tolist())
c.write(sys.argv[2])
"""


@pytest.mark.parametrize("layout", ["2xn", "flat"])
def test_events_in_both_time_layouts(written, tmp_path, layout):
    out = tmp_path / f"events_{layout}.c3d"
    subprocess.run([sys.executable, "-c", EVENT_WRITER, str(written), str(out), layout], check=True)
    events = read_c3d(out).events
    assert list(events.columns) == list(EVENT_COLUMNS)
    assert events[["context", "label"]].values.tolist() == [
        ["Left", "Foot Strike"],
        ["Right", "Foot Off"],
        ["Left", "Foot Off"],
    ]
    np.testing.assert_allclose(events["time_s"], [0.05, 0.12, 60.5], rtol=0, atol=1e-6)  # float32 in the file


def test_file_without_events_has_an_empty_table(written):
    events = read_c3d(written).events
    assert len(events) == 0 and list(events.columns) == list(EVENT_COLUMNS)
    assert events["time_s"].dtype == float


def test_event_times_of_odd_length_are_refused(written, tmp_path):
    script = EVENT_WRITER.replace('times if sys.argv[3] == "2xn" else times.T.ravel().tolist()', "[0.0, 0.1, 0.0]")
    out = tmp_path / "odd.c3d"
    subprocess.run([sys.executable, "-c", script, str(written), str(out), "flat"], check=True)
    with pytest.raises(LoperInputError, match=r"odd.c3d: EVENT:TIMES must hold \(minutes, seconds\) pairs"):
        read_c3d(out)


def test_first_frame_sets_the_time_base(written, tmp_path):
    """Header word 4 (1-based first frame) = 101: frame k of the file is at (100 + k) / rate."""
    data = bytearray(written.read_bytes())
    assert struct.unpack("<HH", data[6:10]) == (1, N)
    data[6:10] = struct.pack("<HH", 101, 100 + N)
    path = tmp_path / "late.c3d"
    path.write_bytes(bytes(data))
    rec = read_c3d(path)
    assert rec.first_frame == 100
    np.testing.assert_allclose(rec.time_s, (100 + np.arange(N)) / RATE_HZ, rtol=0, atol=1e-12)
    np.testing.assert_allclose(rec.analog_time_s[:3], [1.0, 1.005, 1.01], rtol=0, atol=1e-12)


def test_walking5_has_no_events_and_its_units():
    rec = read_c3d(Path(__file__).parents[1] / "data" / "opensim-core" / "walking5.c3d")
    assert rec.events.equals(
        pd.DataFrame(
            {"context": pd.Series(dtype=object), "label": pd.Series(dtype=object), "time_s": pd.Series(dtype=float)}
        )
    )
    assert rec.first_frame == 0 and rec.point_rate_hz == 250.0 and rec.markers_m.shape == (1103, 40, 3)
    assert rec.analog_units == ["N", "N", "N", "Nmm", "Nmm", "Nmm"] * 2
