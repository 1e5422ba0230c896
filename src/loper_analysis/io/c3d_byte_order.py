"""C3D files written on a MIPS (SGI) processor: big-endian integers and IEEE floats.

The C3D standard (c3d.org, "The C3D File Format User Guide", chapter 3)
names three processor types in byte 4 of the parameter section: 84 Intel,
85 DEC and 86 MIPS. ezc3d reads the first two and refuses the third, so a
MIPS file is turned into its Intel twin, byte for byte, before ezc3d reads
it: every 2-byte integer and 4-byte float of the header, the parameter
records and the data block is reversed; characters and 1-byte values stay.

The data block holds one kind of word throughout: 4-byte floats when
``POINT:SCALE`` is negative, 16-bit integers otherwise (points and analog
samples alike), so it is reversed in units of that size.
"""

from __future__ import annotations

import contextlib
import os
import struct
import tempfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["INTEL", "MIPS", "ezc3d_readable", "intel_twin", "processor_type"]

#: Processor type bytes of the parameter section (byte 4).
INTEL, DEC, MIPS = 84, 85, 86

_BLOCK_BYTES = 512
# Header words (1-based, 2 bytes each) holding 16-bit integers and 4-byte floats; the rest are characters,
# bytes or reserved. Words 2-6 (points, analog words, first and last frame, gap), 9-10 (data start, analog
# samples per frame), 148-152 (label and event keys, event count); floats: 7-8 (scale), 11-12 (frame rate),
# 153-188 (18 event times).
_HEADER_INTS = [*range(2, 7), 9, 10, *range(148, 153)]
_HEADER_FLOATS = [7, 11, *range(153, 189, 2)]


def processor_type(path: str | os.PathLike) -> int | None:
    """Byte 4 of the parameter section (84 Intel, 85 DEC, 86 MIPS), None when the file is too short to say."""
    with Path(path).open("rb") as fh:
        first = fh.read(1)
        if not first:
            return None
        fh.seek(max(first[0] - 1, 0) * _BLOCK_BYTES + 3)
        byte = fh.read(1)
    return byte[0] if byte else None


def _reverse(raw: bytearray, start: int, stop: int, size: int) -> None:
    """Reverse the byte order of the ``size``-byte words in ``raw[start:stop]`` in place."""
    stop = start + (stop - start) // size * size
    words = np.frombuffer(bytes(raw[start:stop]), dtype=np.uint8).reshape(-1, size)
    raw[start:stop] = words[:, ::-1].tobytes()


def _word(raw: bytearray, word: int, size: int) -> None:
    start = 2 * (word - 1)
    _reverse(raw, start, start + size, size)


def _parameter_records(raw: bytearray, start: int, end: int) -> float:
    """Reverse the parameter records' offsets and numbers in place; ``POINT:SCALE`` (as read) is returned."""
    groups: dict[int, str] = {}
    scale = -1.0
    pos = start + 4
    while pos + 2 <= end:
        n_chars, ident = struct.unpack("bb", raw[pos : pos + 2])
        if n_chars == 0:
            break
        label = raw[pos + 2 : pos + 2 + abs(n_chars)].decode("latin-1").upper()
        here = pos + 2 + abs(n_chars)
        _reverse(raw, here, here + 2, 2)
        (step,) = struct.unpack("<h", raw[here : here + 2])
        if ident > 0:
            kind, n_dims = struct.unpack("bb", raw[here + 2 : here + 4])
            dims = list(raw[here + 4 : here + 4 + n_dims])
            data = here + 4 + n_dims
            count = int(np.prod(dims)) if dims else 1
            if kind in (2, 4):
                if data + count * kind > end:
                    raise ValueError(f"parameter {label} runs past the parameter section")
                _reverse(raw, data, data + count * kind, kind)
            if groups.get(ident) == "POINT" and label == "SCALE" and kind == 4:
                scale = struct.unpack("<f", raw[data : data + 4])[0]
        else:
            groups[-ident] = label
        if step <= 0:
            break
        pos = here + step
    return scale


def intel_twin(raw: bytes, source: str = "C3D file") -> bytes:
    """The bytes of a MIPS C3D file in Intel order (processor type 84); other files are returned unchanged.

    Raises
    ------
    LoperInputError
        A header or parameter section that cannot be walked (naming ``source``).
    """
    if len(raw) < _BLOCK_BYTES or raw[0] < 2:
        return raw
    start = (raw[0] - 1) * _BLOCK_BYTES
    if len(raw) < start + 4 or raw[start + 3] != MIPS:
        return raw
    out = bytearray(raw)
    for word in _HEADER_INTS:
        _word(out, word, 2)
    for word in _HEADER_FLOATS:
        _word(out, word, 4)
    end = start + max(raw[start + 2], 1) * _BLOCK_BYTES
    try:
        scale = _parameter_records(out, start, min(end, len(out)))
    except (struct.error, ValueError) as exc:
        raise LoperInputError(f"{source}: damaged parameter section of a MIPS C3D file: {exc}") from None
    out[start + 3] = INTEL
    (data_block,) = struct.unpack("<H", out[16:18])
    data_start = (max(data_block, 1) - 1) * _BLOCK_BYTES
    _reverse(out, data_start, len(out), 4 if scale < 0 else 2)
    return bytes(out)


@contextlib.contextmanager
def ezc3d_readable(path: str | os.PathLike) -> Iterator[Path]:
    """A path ezc3d can read for ``path``: the file itself, or for a MIPS file its Intel twin in a
    temporary folder that is removed on leaving the block."""
    path = Path(path)
    if processor_type(path) != MIPS:
        yield path
        return
    twin = intel_twin(path.read_bytes(), str(path))
    with tempfile.TemporaryDirectory(prefix="loper-c3d-") as folder:
        copy = Path(folder) / path.name
        copy.write_bytes(twin)
        yield copy
