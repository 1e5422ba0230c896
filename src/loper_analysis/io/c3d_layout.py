"""A C3D file's layout against its parameters: the raw header's words, and the checks that refuse rates,
storage formats and data blocks that disagree with what the parameters declare (each naming the file, the
parameter and its value). Used by :func:`loper_analysis.io.c3d.read_c3d`.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_parameters import (
    param_value,
)

__all__ = [
    "check_complete",
    "check_rates",
    "check_storage_format",
    "check_zeroed_tail",
    "header_frames",
    "raw_header",
    "zeroed_tail_frames",
]


#: Size of a C3D block (header, parameter and data sections start on block boundaries), bytes.
_BLOCK_BYTES = 512


def raw_header(path: Path) -> dict:
    """Words of the raw C3D header (first 512 bytes) that ezc3d may adjust in its own copy.

    ``analog_words`` (word 3: analog values per frame, all channels),
    ``first``/``last`` (words 4, 5: 1-based frames), ``samples_per_frame``
    (word 10: analog samples per frame and channel) and ``point_rate_hz``
    (words 11-12, float; DEC floats converted).
    """
    with path.open("rb") as fh:
        head = fh.read(512)
        fh.seek(max(head[0] - 1, 0) * 512 + 3)
        processor = fh.read(1)
    big = processor == bytes([86])  # 84 Intel, 85 DEC: little-endian integers; 86 MIPS
    order = ">" if big else "<"
    analog_words, first, last = struct.unpack(order + "HHH", head[4:10])
    (samples_per_frame,) = struct.unpack(order + "H", head[18:20])
    if processor == bytes([85]):  # DEC F-float: 16-bit halves swapped, exponent bias 2 higher
        rate = struct.unpack("<f", head[22:24] + head[20:22])[0] / 4.0
    else:
        rate = struct.unpack(order + "f", head[20:24])[0]
    return {
        "analog_words": analog_words,
        "first": first,
        "last": last,
        "samples_per_frame": samples_per_frame,
        "point_rate_hz": float(rate),
    }


def header_frames(path: Path) -> int | None:
    """Frame count from the raw C3D header (words 4 and 5, 1-based first and last frame).

    ezc3d lowers its own header copy to the frames it could read, so a
    truncated file cannot be recognised from ezc3d's header. None when the
    header cannot tell (last frame saturated at 65535 in long files).
    """
    head = raw_header(path)
    first, last = head["first"], head["last"]
    if last >= 0xFFFF or last < first:
        return None
    return last - first + 1


def check_rates(path: Path, point_rate: float, analog_rate: float, ratio: int, n_channels: int) -> None:
    """Refuse ``POINT:RATE``, ``ANALOG:RATE`` or ``ANALOG:USED`` that disagree with the header's data layout.

    ezc3d splits the analog block by ``ANALOG:RATE``: a wrong but integer
    ratio (512 Hz declared, 1024 Hz recorded) reads every other sample as the
    next frame's without complaint.
    """
    source = str(path)
    head = raw_header(path)
    rate = head["point_rate_hz"]
    if np.isfinite(rate) and rate > 0 and abs(rate - point_rate) > 1e-3 * point_rate:
        raise LoperInputError(
            f"{source}: POINT:RATE = {point_rate:g} Hz disagrees with the header's frame rate {rate:g} Hz"
        )
    if not n_channels:
        return
    per_frame = head["samples_per_frame"] or (head["analog_words"] // n_channels if head["analog_words"] else 0)
    if per_frame and per_frame != ratio:
        raise LoperInputError(
            f"{source}: ANALOG:RATE = {analog_rate:g} Hz gives {ratio} analog samples per frame at POINT:RATE = "
            f"{point_rate:g} Hz, but the data block holds {per_frame} per frame (header word 10; "
            f"{per_frame * point_rate:g} Hz)"
        )
    if head["analog_words"] and head["analog_words"] != n_channels * ratio:
        raise LoperInputError(
            f"{source}: ANALOG:USED = {n_channels} channels at {ratio} samples per frame disagrees with the "
            f"header's {head['analog_words']} analog values per frame (header word 3)"
        )


def check_storage_format(path: Path, data_start: int, scale: float, n_frames: int, words_per_frame: int) -> None:
    """Refuse a data block whose size fits the other storage format than the one ``POINT:SCALE`` declares.

    ``POINT:SCALE`` < 0 declares 4-byte floats, > 0 16-bit integers (every
    word of a frame, point and analog alike). ezc3d reads the block in the
    declared format without checking its size: float data declared as
    integers comes back as garbage frames, integer data declared as floats as
    half the frames. Refused only when the bytes after ``POINT:DATA_START``
    fit the other format and not the declared one (:func:`_fits`: files may
    be padded to a block end and carry one spare block), and, for declared
    integers, when the bytes after the declared data are not all zero
    (zeros are padding or spare blocks, not float frames).
    """
    words = int(n_frames) * int(words_per_frame)
    if words <= 0:
        return
    as_float = scale < 0
    declared_bytes, other_bytes = (4, 2) if as_float else (2, 4)
    data_at = (int(data_start) - 1) * _BLOCK_BYTES
    present = path.stat().st_size - data_at
    need, need_other = words * declared_bytes, words * other_bytes
    if not _fits(present, need_other) or _fits(present, need):
        return
    if not as_float and not any(_tail(path, data_at + need)):
        return  # zeros after the declared block: padding or spare blocks, not float data
    sizes = (
        f"{n_frames} frames of {words_per_frame} words need {need} bytes as "
        f"{'4-byte floats' if as_float else '16-bit integers'} ({need_other} as "
        f"{'16-bit integers' if as_float else '4-byte floats'}) after POINT:DATA_START = {int(data_start)} "
        f"(byte {data_at}); the file holds {present} bytes there"
    )
    if as_float:
        raise LoperInputError(
            f"{path}: POINT:SCALE = {scale:g} (negative) declares 4-byte float data, but the data block "
            f"is the size of 16-bit integer data: {sizes}. POINT:SCALE has the wrong sign (integer data need a "
            "positive scale), or the file was cut at that size"
        )
    raise LoperInputError(
        f"{path}: POINT:SCALE = {scale:g} (positive) declares 16-bit integer data, but the data block "
        f"holds twice those bytes, the size of 4-byte float data: {sizes}. POINT:SCALE has the wrong sign "
        "(float data need a negative scale); read as integers the frames would be garbage"
    )


def check_complete(c3d, path: Path, n_frames: int, words_per_frame: int) -> None:
    """Refuse a file whose data block does not match its header and ``POINT:SCALE``.

    Checked in this order: the data block's size against the storage format
    ``POINT:SCALE`` declares (:func:`_check_storage_format`; with the raw
    header's frame count, which ezc3d lowers in its own copy), then a file
    shorter than its header says (ezc3d reads truncated files silently).
    """
    source = str(path)
    declared = header_frames(path)
    params = c3d["parameters"]
    start = param_value(params, "POINT", "DATA_START")
    scale = param_value(params, "POINT", "SCALE")
    if start is None or len(start) == 0:
        raise LoperInputError(f"{source}: POINT:DATA_START not declared")
    scale_value = None if scale is None or len(scale) == 0 else float(np.ravel(scale)[0])
    if scale_value is not None and np.isfinite(scale_value):
        check_storage_format(
            path, int(start[0]), scale_value, n_frames if declared is None else declared, words_per_frame
        )
    if declared is not None and n_frames < declared:
        raise LoperInputError(
            f"{source}: truncated file: the header declares {declared} frames but only {n_frames} could be read"
        )
    word_bytes = 4 if scale_value is None or scale_value < 0 else 2
    needed = (int(start[0]) - 1) * _BLOCK_BYTES + n_frames * words_per_frame * word_bytes
    size = path.stat().st_size
    if size < needed:
        raise LoperInputError(
            f"{source}: truncated file: {n_frames} frames of {words_per_frame} words need {needed} bytes, "
            f"the file has {size}"
        )


#: Frames read at a time when looking for the zeroed frames at a data block's end.
_TAIL_CHUNK_FRAMES = 4096


def zeroed_tail_frames(path: Path, data_start: int, n_frames: int, frame_bytes: int) -> int:
    """How many of the last frames of the data block hold nothing but zero bytes (0 when the last one holds any).

    ``data_start``: ``POINT:DATA_START`` (1-based block); ``frame_bytes``: one frame's record, every point's
    four words (X, Y, Z, residual) and every analog sample. A recorded frame never holds only zero bytes: a
    marker seen has its coordinates, a marker missing has residual -1 (QTM, Nexus, ezc3d and
    :mod:`loper_analysis.io.c3d_writer` all write it so), and analog channels hold the converter's noise. The
    frames are read from the end backwards, a chunk at a time.
    """
    if n_frames <= 0 or frame_bytes <= 0:
        return 0
    offset = (int(data_start) - 1) * _BLOCK_BYTES
    zeroed, end = 0, n_frames
    with path.open("rb") as fh:
        while end > 0:
            begin = max(end - _TAIL_CHUNK_FRAMES, 0)
            fh.seek(offset + begin * frame_bytes)
            chunk = np.frombuffer(fh.read((end - begin) * frame_bytes), np.uint8)
            rows = chunk[: (chunk.size // frame_bytes) * frame_bytes].reshape(-1, frame_bytes).any(axis=1)
            held = np.flatnonzero(rows)
            if held.size:
                return zeroed + (rows.size - 1 - int(held[-1]))
            zeroed += rows.size
            end = begin
    return zeroed


def check_zeroed_tail(
    c3d, path: Path, n_frames: int, words_per_frame: int, point_rate_hz: float, n_channels: int
) -> None:
    """Refuse a file whose last frames hold zero bytes only: an interrupted copy or export.

    The frames' bytes all 0 read as every marker at exactly (0, 0, 0) with a valid residual (and every analog
    sample 0); the reader would take them as frames where every marker is missing, and the trial would go on with
    its first part only. No recorded file holds such a frame (:func:`zeroed_tail_frames`), so one zeroed frame at
    the end is refused, naming the first zeroed frame, its time and the zeroed share of the trial.
    """
    params = c3d["parameters"]
    start = param_value(params, "POINT", "DATA_START")
    scale = param_value(params, "POINT", "SCALE")
    scale_value = None if scale is None or len(scale) == 0 else float(np.ravel(scale)[0])
    word_bytes = 4 if scale_value is None or not np.isfinite(scale_value) or scale_value < 0 else 2
    zeroed = zeroed_tail_frames(path, int(start[0]), n_frames, words_per_frame * word_bytes)
    if not zeroed:
        return
    first = n_frames - zeroed + 1  # 1-based frame of the file
    analogs = ", every analog sample 0" if n_channels else ""
    pct = 100.0 * zeroed / n_frames
    share = f"{pct:.0f}" if pct >= 1 else f"{pct:.1g}"
    raise LoperInputError(
        f"{path}: the last {zeroed} of {n_frames} frames ({share} % of the trial) hold "
        f"zeros only, from frame {first} at {(first - 1) / point_rate_hz:.3f} s on (every marker at exactly "
        f"(0, 0, 0){analogs}): likely an interrupted copy or export: the file's last {zeroed} frames hold zeros; "
        "copy or export the trial again from the capture system"
    )


def _blocks(n_bytes: int) -> int:
    """``n_bytes`` rounded up to whole 512-byte blocks (C3D sections end on a block boundary)."""
    return -(-int(n_bytes) // _BLOCK_BYTES) * _BLOCK_BYTES


def _fits(present: int, needed: int) -> bool:
    """Whether ``present`` bytes hold a data block of ``needed`` bytes: at least that many, and at most
    the block-rounded size plus one spare block (padding, a trailing block)."""
    return needed <= present <= _blocks(needed) + _BLOCK_BYTES


def _tail(path: Path, offset: int) -> bytes:
    """The bytes of the file from ``offset`` to its end."""
    with path.open("rb") as fh:
        fh.seek(offset)
        return fh.read()
