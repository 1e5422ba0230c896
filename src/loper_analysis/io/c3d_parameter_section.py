"""One parameter of a C3D file, read from its parameter section alone.

The workflow decides what to make of a recorded trial (force platforms or
belt channels) before any job runs. ezc3d reads the whole file, data
included; this module reads only the 512-byte header and the parameter
blocks, so the decision costs a few kilobytes per file whatever the
trial's length. The layout is the C3D standard's (c3d.org, "The C3D File
Format User Guide", chapter 3): processor type at byte 4 of the parameter
section, then group and parameter records linked by their offsets.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["read_parameter", "force_platforms_used"]

_PROCESSORS = {84: "<", 85: "<", 86: ">"}  # Intel, DEC (little-endian integers), MIPS


def _floats(raw: bytes, order: str, dec: bool) -> np.ndarray:
    """4-byte floats: IEEE in the given byte order, or DEC F-floats (16-bit halves swapped, exponent bias 2 higher)."""
    if dec:
        swapped = b"".join(raw[i + 2 : i + 4] + raw[i : i + 2] for i in range(0, len(raw), 4))
        return np.frombuffer(swapped, "<f4").astype(float) / 4.0
    return np.frombuffer(raw, order + "f4").astype(float)


def read_parameter(path: str | os.PathLike, group: str, name: str):
    """The value of parameter ``group:name`` of a C3D file, or None when the file has no such parameter.

    Returns
    -------
    numpy.ndarray or str or None
        Numbers as an array of the parameter's C3D dimensions (as ezc3d
        gives them: the first dimension varies fastest in the file; a scalar
        as shape ``(1,)``), characters as one string (trailing blanks removed).

    Raises
    ------
    LoperInputError
        A file whose header or parameter section cannot be read (naming the file and the byte offset).
    """
    source = str(path)
    try:
        with Path(path).open("rb") as fh:
            head = fh.read(512)
            if len(head) < 512:
                raise LoperInputError(f"{source}: not a C3D file: {len(head)} bytes, shorter than its header")
            start = (head[0] - 1) * 512
            fh.seek(start)
            first = fh.read(512)
            if len(first) < 4 or first[3] not in _PROCESSORS:
                raise LoperInputError(f"{source}: not a C3D file: no parameter section at byte {start}")
            section = first + fh.read(max(first[2] - 1, 0) * 512)
    except OSError as exc:
        raise LoperInputError(f"{source}: cannot read the C3D file ({exc.strerror or exc})") from None
    order, dec = _PROCESSORS[section[3]], section[3] == 85
    groups: dict[int, str] = {}
    pos = 4
    try:
        while pos + 2 <= len(section):
            n_chars, ident = struct.unpack("bb", section[pos : pos + 2])
            if n_chars == 0:
                break
            label = section[pos + 2 : pos + 2 + abs(n_chars)].decode("latin-1").upper()
            here = pos + 2 + abs(n_chars)
            (step,) = struct.unpack(order + "h", section[here : here + 2])
            if ident < 0:
                groups[-ident] = label
            elif groups.get(ident) == group.upper() and label == name.upper():
                return _value(section, here + 2, order, dec)
            if step <= 0:
                break
            pos = here + step
    except (struct.error, ValueError, UnicodeDecodeError) as exc:
        raise LoperInputError(f"{source}: damaged C3D parameter section at byte {start + pos}: {exc}") from None
    return None


def _value(section: bytes, pos: int, order: str, dec: bool):
    """The value of the parameter record whose type byte is at ``pos``."""
    kind, n_dims = struct.unpack("bb", section[pos : pos + 2])
    dims = list(section[pos + 2 : pos + 2 + n_dims])
    data = pos + 2 + n_dims
    count = int(np.prod(dims)) if dims else 1
    size = count * abs(kind)
    raw = section[data : data + size]
    if len(raw) < size:
        raise ValueError(f"parameter data of {size} bytes runs past the section")
    if kind == -1:
        return raw.decode("latin-1").rstrip()
    if kind == 1:
        values = np.frombuffer(raw, "i1").astype(int)
    elif kind == 2:
        values = np.frombuffer(raw, order + "i2").astype(int)
    elif kind == 4:
        values = _floats(raw, order, dec)
    else:
        raise ValueError(f"unknown parameter type {kind}")
    return values.reshape(dims, order="F") if dims else values


def force_platforms_used(path: str | os.PathLike) -> int:
    """``FORCE_PLATFORM:USED`` of a C3D file: its number of force platforms, 0 when the parameter is absent."""
    used = read_parameter(path, "FORCE_PLATFORM", "USED")
    if used is None or isinstance(used, str) or used.size == 0:
        return 0
    return int(used.flat[0])
