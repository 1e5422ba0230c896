"""Writing C3D motion-capture files with ``ezc3d``.

Float C3D with ``POINT:RATE/LABELS/UNITS`` and ``ANALOG:RATE/LABELS/UNITS``
set explicitly and ``ANALOG:SCALE`` 1, ``OFFSET`` 0, ``GEN_SCALE`` 1, so a
round trip through :func:`loper_analysis.io.c3d.read_c3d` is exact to
float32. A missing (NaN) point is stored as (0, 0, 0) with residual -1.
Writing goes through the atomic writer (:func:`loper_analysis.io.atomic.staged`)
and is deterministic: the same inputs give the same bytes. ezc3d's writer
runs in a child Python process, because in-process it breaks OpenSim's
vector arguments or is broken by them (:func:`write_c3d`, Notes).
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..checks import positive, unique_names
from ..errors import LoperInputError
from .atomic import staged
from .c3d import LENGTH_UNITS_PER_M, C3DRecording, rate_ratio

__all__ = ["MAX_LABEL_CHARS", "write_c3d", "write_recording"]

#: Longest label ezc3d can write and read back (longer ones give an unreadable file).
MAX_LABEL_CHARS = 255
_FLOAT32_MAX = float(np.finfo(np.float32).max)


def _labels(labels: Sequence[str], what: str, n: int, source: str) -> list[str]:
    """n unique, non-empty labels of at most :data:`MAX_LABEL_CHARS` characters without edge blanks."""
    labels = list(labels)
    if len(labels) != n:
        raise LoperInputError(f"{source}: {what} must name {n} item(s), got {len(labels)}")
    return unique_names(labels, what, source, max_chars=MAX_LABEL_CHARS)


def _points_for_file(markers_m, units_per_m: float, source: str) -> tuple[np.ndarray, np.ndarray]:
    """ezc3d points (4, n_markers, n_frames) and residuals (1, n_markers, n_frames); NaN -> 0 with residual -1."""
    X = np.asarray(markers_m, dtype=float)
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[0] < 1 or X.shape[1] < 1:
        raise LoperInputError(f"{source}: markers_m must have shape (n_frames >= 1, n_markers >= 1, 3), got {X.shape}")
    scaled = X * units_per_m
    too_big = np.abs(np.nan_to_num(scaled, nan=0.0)) > _FLOAT32_MAX  # inf included; NaN means missing
    if np.any(too_big):
        f, m, _ = np.argwhere(too_big)[0]
        raise LoperInputError(f"{source}: markers_m[{f}, {m}] = {X[f, m]} is not finite in float32")
    missing = ~np.all(np.isfinite(scaled), axis=2)  # (n_frames, n_markers)
    scaled[missing] = 0.0
    points = np.ones((4, X.shape[1], X.shape[0]))
    points[:3] = np.transpose(scaled, (2, 1, 0))
    residuals = np.where(missing.T, -1.0, 0.0)[np.newaxis]
    return points, residuals


def _analogs_for_file(analogs, n_channels: int, n_samples: int, source: str) -> np.ndarray:
    """ezc3d analogs (1, n_channels, n_samples) from (n_samples, n_channels); refuses wrong shapes and non-finite values."""
    A = np.zeros((n_samples, 0)) if analogs is None else np.asarray(analogs, dtype=float)
    if A.ndim != 2 or A.shape != (n_samples, n_channels):
        raise LoperInputError(
            f"{source}: analogs must have shape (n_frames * samples per frame = {n_samples}, "
            f"n_channels = {n_channels}), got {A.shape}"
        )
    bad = np.isnan(A) | (np.abs(np.nan_to_num(A)) > _FLOAT32_MAX)  # inf included
    if np.any(bad):
        k, ch = np.argwhere(bad)[0]
        raise LoperInputError(f"{source}: analogs[{k}, {ch}] = {A[k, ch]} is not finite in float32")
    return A.T[np.newaxis]


def _write_in_child(payload: dict[str, np.ndarray], out: Path, source: str) -> None:
    """Write ``out`` with ezc3d in a fresh Python process (see :func:`write_c3d`, Notes)."""
    payload_path = out.with_name(out.name + ".payload.npz")
    np.savez(payload_path, **payload)
    proc = subprocess.run(
        [sys.executable, "-m", "loper_analysis.io.ezc3d_child", str(payload_path), str(out)], capture_output=True, text=True
    )
    if proc.returncode != 0 or not out.is_file():
        lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
        raise LoperInputError(f"{source}: ezc3d could not write the file: {lines[-1] if lines else 'no message'}")


def write_c3d(
    path: str | os.PathLike,
    marker_labels: Sequence[str],
    markers_m,
    point_rate_hz: float,
    analog_labels: Sequence[str] = (),
    analogs=None,
    analog_units: Sequence[str] = (),
    analog_rate_hz: float | None = None,
    point_unit: str = "mm",
) -> Path:
    """Write markers (given in m) and analog channels to a float C3D file, atomically; returns ``path``.

    Parameters
    ----------
    path : str or path-like
        Target ``.c3d`` file (a missing directory is created).
    marker_labels : sequence of str
        One unique label per marker (at most 255 characters, no edge blanks).
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres; a point with any NaN
        coordinate is written as missing ((0, 0, 0), residual -1). A point
        exactly at (0, 0, 0) m is read back as missing (:func:`read_c3d`).
    point_rate_hz : float
        Frame rate (Hz).
    analog_labels, analog_units : sequence of str
        One label and one unit (e.g. ``"N"``, ``"V"``) per analog channel.
    analogs : array_like, optional
        Shape (n_frames * ratio, n_channels), finite, in the channels' units.
    analog_rate_hz : float, optional
        Analog rate (Hz), an integer multiple ``ratio`` of ``point_rate_hz``;
        default ``point_rate_hz``.
    point_unit : {"mm", "cm", "m"}
        Unit stored in ``POINT:UNITS``; coordinates are float32 in that unit.

    Raises
    ------
    LoperInputError
        Bad shapes, labels, units, rates (including a non-integer
        analog/point rate ratio), non-finite analogs, values beyond float32,
        or a failed write; nothing is left behind.

    Notes
    -----
    ezc3d's writer runs in a child Python process: in one process, ezc3d's
    and OpenSim's SWIG wrappers share the converters of ``std::vector``
    (process-wide ``STB_GNU_UNIQUE`` statics), and whichever library uses
    them first breaks the other's vector arguments (an in-process ezc3d write
    makes ``opensim.StdVectorDouble`` arguments raise TypeError; earlier
    OpenSim use makes ezc3d's write raise TypeError). Reading is unaffected.
    """
    path = Path(path)
    source = str(path)
    unit = str(point_unit).lower()
    if unit not in LENGTH_UNITS_PER_M:
        raise LoperInputError(f"{source}: point_unit must be one of {', '.join(LENGTH_UNITS_PER_M)}, got {point_unit!r}")
    point_rate = positive("point_rate_hz", point_rate_hz, source)
    points, residuals = _points_for_file(markers_m, LENGTH_UNITS_PER_M[unit], source)
    labels = _labels(marker_labels, "marker_labels", points.shape[1], source)
    a_labels = list(analog_labels)
    n_ch = len(a_labels)
    if n_ch == 0 and analogs is not None and np.size(analogs) > 0:
        raise LoperInputError(f"{source}: analogs given without analog_labels")
    analog_rate = point_rate if analog_rate_hz is None else positive("analog_rate_hz", analog_rate_hz, source)
    ratio = rate_ratio(point_rate, analog_rate, source)
    if n_ch:
        a_labels = _labels(a_labels, "analog_labels", n_ch, source)
        a_units = [str(u) for u in analog_units]
        if len(a_units) != n_ch:
            raise LoperInputError(f"{source}: analog_units must give one unit per channel ({n_ch}), got {len(a_units)}")
        samples = _analogs_for_file(analogs, n_ch, points.shape[2] * ratio, source)

    payload = {
        "point_rate_hz": np.float64(point_rate),
        "point_unit": np.str_(unit),
        "marker_labels": np.array(labels, dtype=str),
        "points": points,
        "residuals": residuals,
        "analog_rate_hz": np.float64(analog_rate),
        "analog_labels": np.array(a_labels if n_ch else [], dtype=str),
        "analog_units": np.array(a_units if n_ch else [], dtype=str),
        "analogs": samples if n_ch else np.zeros((1, 0, 0)),
    }
    with staged(path, "C3D file") as tmp:
        _write_in_child(payload, tmp, source)
    return path


def write_recording(path: str | os.PathLike, recording: C3DRecording, point_unit: str = "mm") -> Path:
    """Write a :class:`~loper_analysis.io.c3d.C3DRecording` (markers and analogs) with :func:`write_c3d`."""
    return write_c3d(path, recording.marker_labels, recording.markers_m, recording.point_rate_hz,
                     recording.analog_labels, recording.analogs if recording.analog_labels else None,
                     recording.analog_units, recording.analog_rate_hz, point_unit)
