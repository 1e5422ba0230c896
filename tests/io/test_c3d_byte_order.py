"""C3D files of the MIPS processor type (SGI, big-endian) read as their Intel twins.

The MIPS files are written here from the labs' own Intel files by a converter of this test's own, which reads
every value before it reverses it (the reader's reverses first and reads after), so the two walk the C3D
standard's layout independently: header words, parameter records, and a data block of floats or of 16-bit
integers. Known answers: the lab's Intel file, byte for byte, and what the readers make of it.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_byte_order import INTEL, MIPS, intel_twin, processor_type
from loper_analysis.io.c3d_parameter_section import read_parameter
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.force_platforms import read_c3d_with_platforms
from tests.bad_input.test_c3d_guards import integer_copy

ROOT = Path(__file__).resolve().parents[2]
LAB_FILES = sorted((ROOT / "tests" / "data" / "c3d-parser").glob("*/*.c3d")) + [
    ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
]


def _reverse(data: bytearray, start: int, size: int, count: int = 1) -> None:
    stop = start + size * count
    data[start:stop] = np.frombuffer(bytes(data[start:stop]), np.uint8).reshape(count, size)[:, ::-1].tobytes()


def mips_copy(raw: bytes) -> bytes:
    """An Intel C3D file's bytes as a MIPS processor writes them (the C3D User Guide, chapter 3)."""
    data = bytearray(raw)
    start = (data[0] - 1) * 512
    assert data[start + 3] == INTEL
    (data_block,) = struct.unpack_from("<H", data, 16)
    for word in (2, 3, 4, 5, 6, 9, 10, 148, 149, 150, 151, 152):  # header integers
        _reverse(data, 2 * (word - 1), 2)
    for word in (7, 11, *range(153, 189, 2)):  # scale, frame rate, 18 event times
        _reverse(data, 2 * (word - 1), 4)
    pos, groups, scale = start + 4, {}, None
    while True:
        n_chars, ident = struct.unpack_from("<bb", data, pos)
        if n_chars == 0:
            break
        name = bytes(data[pos + 2 : pos + 2 + abs(n_chars)]).decode("latin-1").upper()
        at = pos + 2 + abs(n_chars)
        (step,) = struct.unpack_from("<h", data, at)
        _reverse(data, at, 2)
        if ident < 0:
            groups[-ident] = name
        else:
            kind, n_dims = struct.unpack_from("<bb", data, at + 2)
            values = at + 4 + n_dims
            count = int(np.prod(list(data[at + 4 : values]))) if n_dims else 1
            if (groups.get(ident), name) == ("POINT", "SCALE"):
                (scale,) = struct.unpack_from("<f", data, values)
            if kind in (2, 4):
                _reverse(data, values, kind, count)
        if step <= 0:
            break
        pos = at + step
    data[start + 3] = MIPS
    size = 4 if scale < 0 else 2
    first = (data_block - 1) * 512
    _reverse(data, first, size, (len(data) - first) // size)
    return bytes(data)


@pytest.mark.parametrize("path", LAB_FILES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_the_intel_twin_of_a_labs_file_written_by_a_mips_processor_is_the_labs_file(path):
    raw = path.read_bytes()
    mips = mips_copy(raw)
    assert mips != raw
    points = len(read_c3d(path).marker_labels) + 0  # header word 2 counts every point, markers and model outputs
    assert struct.unpack_from(">H", mips, 2)[0] >= points  # big-endian now
    assert intel_twin(mips, str(path)) == raw
    assert intel_twin(raw) is raw  # an Intel file is left as it is


def test_a_mips_file_reads_as_its_intel_twin_with_its_plates_and_parameters(tmp_path):
    """The lab whose foot crosses two of its three plates (SYD): markers, channels, plates, events and parameters."""
    intel = ROOT / "tests" / "data" / "c3d-parser" / "SYD" / "walk-nodevice.c3d"
    mips = tmp_path / "walk.c3d"
    mips.write_bytes(mips_copy(intel.read_bytes()))
    assert processor_type(mips) == MIPS and processor_type(intel) == INTEL
    (a, plates_a), (b, plates_b) = read_c3d_with_platforms(intel), read_c3d_with_platforms(mips)
    np.testing.assert_array_equal(b.markers_m, a.markers_m)
    np.testing.assert_array_equal(b.analogs, a.analogs)
    assert b.marker_labels == a.marker_labels and b.analog_labels == a.analog_labels
    assert b.events.equals(a.events) and b.processing == a.processing
    assert len(plates_b) == len(plates_a) == 3
    for p, q in zip(plates_a, plates_b, strict=True):
        np.testing.assert_array_equal(q.force_n, p.force_n)
        np.testing.assert_array_equal(q.corners_m, p.corners_m)
    for group, name in (("FORCE_PLATFORM", "CORNERS"), ("POINT", "LABELS"), ("POINT", "RATE"), ("ANALOG", "SCALE")):
        np.testing.assert_array_equal(read_parameter(mips, group, name), read_parameter(intel, group, name))


def test_a_mips_file_of_16_bit_integers_reads_as_its_intel_twin(tmp_path):
    rng = np.random.default_rng(5)
    X = 0.2 + 0.5 * rng.random((40, 3, 3))
    X[7, 2] = np.nan
    A = np.round(rng.normal(0.0, 300.0, (320, 2)))
    floats = write_c3d(tmp_path / "floats.c3d", ["A", "B", "C"], X, 100.0, ["F1", "F2"], A, ["N", "N"], 800.0)
    ints = integer_copy(floats, tmp_path / "ints.c3d", 0.1, 3, 4 * 3 + 2 * 8, 40)
    mips = tmp_path / "ints_mips.c3d"
    mips.write_bytes(mips_copy(ints.read_bytes()))
    rec = read_c3d(mips)
    assert np.nanmax(np.abs(rec.markers_m - X)) < 0.05e-3  # half of POINT:SCALE's 0.1 mm step
    assert np.isnan(rec.markers_m).sum() == 3
    np.testing.assert_array_equal(rec.analogs, A)


def test_a_mips_parameter_running_past_its_section_names_the_file(tmp_path):
    """The first parameter record declared as floats of 255 x 255 values: more than the section holds."""
    raw = bytearray(mips_copy((ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d").read_bytes()))
    pos = (raw[0] - 1) * 512 + 4
    while struct.unpack_from("bb", raw, pos)[1] < 0:  # past the groups to the first parameter
        n_chars = abs(raw[pos] - 256 if raw[pos] > 127 else raw[pos])
        pos += 2 + n_chars + struct.unpack_from(">h", raw, pos + 2 + n_chars)[0]
    at = pos + 2 + abs(struct.unpack_from("b", raw, pos)[0]) + 2
    raw[at : at + 4] = bytes([4, 2, 255, 255])
    path = tmp_path / "damaged.c3d"
    path.write_bytes(bytes(raw))
    with pytest.raises(LoperInputError, match=rf"^{path}: damaged parameter section of a MIPS C3D file: parameter "):
        read_c3d(path)
