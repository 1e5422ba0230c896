"""A C3D file's layout against its parameters (io.c3d_layout): the raw header's words of a written file and of
hand-built MIPS and DEC headers; rates, storage formats and data blocks that disagree with the parameters refused,
each naming the file, the parameter and its value."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_layout import check_complete, check_rates, check_storage_format, header_frames, raw_header
from loper_analysis.io.c3d_writer import write_c3d

N_FRAMES, N_MARKERS, N_CHANNELS, RATIO = 100, 2, 2, 10
#: Words per frame: x, y, z and residual per marker, then every analog sample of the frame.
WORDS = 4 * N_MARKERS + N_CHANNELS * RATIO
DATA_START = 4  # the writer's parameter section fills blocks 2 and 3
DATA_AT = (DATA_START - 1) * 512


@pytest.fixture
def c3d_file(tmp_path, rng) -> Path:
    """100 frames at 100 Hz from frame 5 (header words 4 and 5: 6 and 105), two markers, two channels at 1 kHz."""
    markers = rng.normal(size=(N_FRAMES, N_MARKERS, 3))
    analogs = rng.normal(size=(N_FRAMES * RATIO, N_CHANNELS))
    return write_c3d(
        tmp_path / "walk01.c3d",
        ["LHEE", "RHEE"],
        markers,
        100.0,
        ["Fz1", "Fz2"],
        analogs,
        ["N", "N"],
        1000.0,
        first_frame=5,
    )


def _read(path: Path):
    import ezc3d

    return ezc3d.c3d(str(path))


def _header_file(path: Path, processor: int, words: bytes, rate: bytes) -> Path:
    """A 512-byte header (parameters at block 2) whose words 3-10 and 11-12 are given, then the parameter block's
    first four bytes with the processor type."""
    head = bytes([2, 0x50]) + words + rate
    path.write_bytes(head + bytes(512 - len(head)) + bytes([1, 80, 1, processor]) + bytes(508))
    return path


def test_the_header_of_a_written_file(c3d_file):
    assert raw_header(c3d_file) == {
        "analog_words": N_CHANNELS * RATIO,
        "first": 6,
        "last": 105,
        "samples_per_frame": RATIO,
        "point_rate_hz": 100.0,
    }
    assert header_frames(c3d_file) == N_FRAMES
    assert c3d_file.stat().st_size == DATA_AT + 4 * N_FRAMES * WORDS  # float data right after the parameters
    assert _read(c3d_file)["parameters"]["POINT"]["DATA_START"]["value"][0] == DATA_START


def test_big_endian_and_dec_headers(tmp_path):
    """MIPS (86): big-endian words and float; DEC (85): little-endian words and an F-float rate, 100.0 stored as
    the words 0x43C8, 0x0000 (IEEE 400.0, exponent bias 2 higher)."""
    # words 2-10 after the first: points, analog words, first, last, max gap, scale (2 words), data start, ratio
    mips = _header_file(
        tmp_path / "mips.c3d", 86, struct.pack(">HHHHHfHH", 2, 20, 1, 250, 0, -0.1, 11, 10), struct.pack(">f", 120.0)
    )
    assert raw_header(mips) == {
        "analog_words": 20,
        "first": 1,
        "last": 250,
        "samples_per_frame": 10,
        "point_rate_hz": 120.0,
    }
    dec = _header_file(
        tmp_path / "dec.c3d",
        85,
        struct.pack("<HHHHH", 2, 8, 3, 52, 0) + bytes(4) + struct.pack("<HH", 11, 4),
        b"\xc8\x43\x00\x00",
    )
    assert raw_header(dec) == {
        "analog_words": 8,
        "first": 3,
        "last": 52,
        "samples_per_frame": 4,
        "point_rate_hz": 100.0,
    }
    assert header_frames(dec) == 50


@pytest.mark.parametrize("first, last", [(1, 0xFFFF), (10, 9)])
def test_header_frames_cannot_tell_a_saturated_or_reversed_range(c3d_file, first, last):
    data = bytearray(c3d_file.read_bytes())
    data[6:10] = struct.pack("<HH", first, last)
    c3d_file.write_bytes(bytes(data))
    assert header_frames(c3d_file) is None


def test_rates_that_agree_with_the_header_pass_and_others_are_named(c3d_file):
    assert check_rates(c3d_file, 100.0, 1000.0, RATIO, N_CHANNELS) is None
    assert check_rates(c3d_file, 100.0, 0.0, 0, 0) is None  # no analog channels: only the frame rate checked
    with pytest.raises(LoperInputError) as err:
        check_rates(c3d_file, 200.0, 2000.0, RATIO, N_CHANNELS)
    assert str(err.value) == f"{c3d_file}: POINT:RATE = 200 Hz disagrees with the header's frame rate 100 Hz"
    with pytest.raises(LoperInputError) as err:
        check_rates(c3d_file, 100.0, 500.0, 5, N_CHANNELS)
    assert str(err.value) == (
        f"{c3d_file}: ANALOG:RATE = 500 Hz gives 5 analog samples per frame at POINT:RATE = 100 Hz, but the data "
        "block holds 10 per frame (header word 10; 1000 Hz)"
    )
    with pytest.raises(LoperInputError) as err:
        check_rates(c3d_file, 100.0, 1000.0, RATIO, 3)
    assert str(err.value) == (
        f"{c3d_file}: ANALOG:USED = 3 channels at 10 samples per frame disagrees with the header's 20 analog "
        "values per frame (header word 3)"
    )


def test_float_data_declared_as_integers_is_named(c3d_file):
    check_storage_format(c3d_file, DATA_START, -1.0, N_FRAMES, WORDS)  # as written: floats, negative scale
    with pytest.raises(LoperInputError) as err:
        check_storage_format(c3d_file, DATA_START, 0.1, N_FRAMES, WORDS)
    assert str(err.value) == (
        f"{c3d_file}: POINT:SCALE = 0.1 (positive) declares 16-bit integer data, but the data block holds twice "
        "those bytes, the size of 4-byte float data: 100 frames of 28 words need 5600 bytes as 16-bit integers "
        "(11200 as 4-byte floats) after POINT:DATA_START = 4 (byte 1536); the file holds 11200 bytes there. "
        "POINT:SCALE has the wrong sign (float data need a negative scale); read as integers the frames would be "
        "garbage"
    )


def test_integer_sized_data_declared_as_floats_is_named_and_zero_padding_is_not(c3d_file):
    c3d_file.write_bytes(c3d_file.read_bytes()[: DATA_AT + 2 * N_FRAMES * WORDS])  # the size of integer data
    with pytest.raises(LoperInputError) as err:
        check_storage_format(c3d_file, DATA_START, -1.0, N_FRAMES, WORDS)
    assert str(err.value).startswith(
        f"{c3d_file}: POINT:SCALE = -1 (negative) declares 4-byte float data, but the data block is the size of "
        "16-bit integer data: 100 frames of 28 words need 11200 bytes as 4-byte floats (5600 as 16-bit integers) "
        "after POINT:DATA_START = 4 (byte 1536); the file holds 5600 bytes there."
    )
    check_storage_format(c3d_file, DATA_START, 0.1, N_FRAMES, WORDS)  # integers of that size: as declared
    c3d_file.write_bytes(c3d_file.read_bytes() + bytes(2 * N_FRAMES * WORDS))  # zeros to the float size
    check_storage_format(c3d_file, DATA_START, 0.1, N_FRAMES, WORDS)  # zeros after integer data: padding


def test_a_complete_file_passes_and_a_cut_one_is_named(c3d_file):
    c3d = _read(c3d_file)
    check_complete(c3d, c3d_file, N_FRAMES, WORDS)
    with pytest.raises(LoperInputError) as err:
        check_complete(c3d, c3d_file, 60, WORDS)  # fewer frames read than the header declares
    assert str(err.value) == f"{c3d_file}: truncated file: the header declares 100 frames but only 60 could be read"
    c3d_file.write_bytes(c3d_file.read_bytes()[:-1000])
    with pytest.raises(LoperInputError) as err:
        check_complete(c3d, c3d_file, N_FRAMES, WORDS)
    assert str(err.value) == f"{c3d_file}: truncated file: 100 frames of 28 words need 12736 bytes, the file has 11736"


def test_a_file_without_data_start_is_named(c3d_file):
    c3d = _read(c3d_file)
    del c3d["parameters"]["POINT"]["DATA_START"]
    with pytest.raises(LoperInputError, match=rf"^{c3d_file}: POINT:DATA_START not declared$"):
        check_complete(c3d, c3d_file, N_FRAMES, WORDS)
