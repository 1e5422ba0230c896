"""Writing C3D motion-capture files with ``ezc3d``.

Float C3D with ``POINT:RATE/LABELS/UNITS`` and ``ANALOG:RATE/LABELS/UNITS``
set explicitly and ``ANALOG:SCALE`` 1, ``OFFSET`` 0, ``GEN_SCALE`` 1, so a
round trip through :func:`loper_analysis.io.c3d.read_c3d` is exact to
float32. A missing (NaN) point is stored as (0, 0, 0) with residual -1.
Writing goes through the atomic writer (:func:`loper_analysis.io.atomic.staged`)
and is deterministic: the same inputs give the same bytes. ezc3d's writer
runs in a child Python process, because in-process it breaks OpenSim's
vector arguments or is broken by them (:func:`write_c3d`, Notes).

Files as a motion-capture system exports them
    Keyword-only extras of :func:`write_c3d` write what a real export holds
    besides markers and channels: a first frame other than 0, the
    ``FORCE_PLATFORM`` group (:class:`ForcePlatform`), per-channel
    ``ANALOG:SCALE`` and ``ANALOG:OFFSET``, and the ``EVENT`` group. Without
    them the file is written exactly as before (same bytes).
"""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.checks import integer, positive, unique_names
from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import staged
from loper_analysis.io.c3d import LENGTH_UNITS_PER_M, C3DRecording, rate_ratio

__all__ = ["MAX_ANALOG_OFFSET", "MAX_LABEL_CHARS", "ForcePlatform", "write_c3d", "write_recording"]

#: Longest label ezc3d can write and read back (longer ones give an unreadable file).
MAX_LABEL_CHARS = 255
#: Largest ``ANALOG:OFFSET`` (a 16-bit integer parameter).
MAX_ANALOG_OFFSET = 32767
#: Largest first frame (0-based): the header stores ``first_frame + 1`` as a 16-bit word.
_MAX_FIRST_FRAME = 65534
_FLOAT32_MAX = float(np.finfo(np.float32).max)
#: Force-platform types written, with their number of channels.
_PLATFORM_CHANNELS = {2: 6, 4: 6}


@dataclass(frozen=True)
class ForcePlatform:
    """One force platform of the ``FORCE_PLATFORM`` group, as the C3D format describes it.

    Attributes
    ----------
    type : int
        2 (six channels: Fx, Fy, Fz in N and Mx, My, Mz in N times the point
        unit, about the plate's sensor origin, in plate coordinates) or 4 (six
        channels, e.g. bridge voltages, turned into those six by ``cal_matrix``).
    corners_m : tuple of 4 (x, y, z) tuples
        Corners of the working surface in the lab frame (m), in the order of
        the plate's quadrants +x+y, -x+y, -x-y, +x-y: the plate's x axis points
        from corner 2 to corner 1, its y axis from corner 4 to corner 1, and its
        z axis is x cross y (downward for a plate in the floor).
    origin_m : tuple of 3 floats
        ``FORCE_PLATFORM:ORIGIN``: the vector from the plate's sensor origin
        (where a force gives no moment) to the geometric centre of the working
        surface, in plate coordinates (m); its z is negative for a sensor origin
        below the surface (C3D format, TYPE-2). Readers take the moments about
        the surface centre as ``M_centre = M_sensor + F x origin``. Corners
        listed the other way round the plate (its z axis up) are written as
        given; ezc3d then moves the moment the wrong way, which
        :func:`loper_analysis.io.force_platforms.read_force_platforms` corrects.
    channels : tuple of 6 ints
        ``FORCE_PLATFORM:CHANNEL``: the 1-based analog channel numbers in the
        order Fx, Fy, Fz, Mx, My, Mz (TYPE 4: the calibration matrix's inputs).
    cal_matrix : tuple of 6 rows of 6 floats, or None
        TYPE 4 only: ``[F; M] = cal_matrix @ channels`` (row = output).
    """

    type: int
    corners_m: tuple
    origin_m: tuple
    channels: tuple
    cal_matrix: tuple | None = None

    def __post_init__(self) -> None:
        source = "ForcePlatform"
        kind = integer("type", self.type, source)
        if kind not in _PLATFORM_CHANNELS:
            raise LoperInputError(f"{source}: type must be one of {sorted(_PLATFORM_CHANNELS)}, got {self.type!r}")
        corners = _finite_array(self.corners_m, (4, 3), "corners_m", source)
        x_axis, y_axis = corners[0] - corners[1], corners[0] - corners[3]
        if np.linalg.norm(np.cross(x_axis, y_axis)) <= 1e-12 * max(1.0, float(np.abs(corners).max()) ** 2):
            raise LoperInputError(f"{source}: corners_m do not span a plane (corners 1-2 and 1-4 are parallel)")
        origin = _finite_array(self.origin_m, (3,), "origin_m", source)
        channels = [
            integer("channels", c, source, minimum=1) for c in np.ravel(np.asarray(self.channels, dtype=object))
        ]
        if len(channels) != _PLATFORM_CHANNELS[kind] or len(set(channels)) != len(channels):
            raise LoperInputError(
                f"{source}: channels must be {_PLATFORM_CHANNELS[kind]} different 1-based channel numbers, "
                f"got {list(self.channels)!r}"
            )
        cal = None
        if kind == 4:
            if self.cal_matrix is None:
                raise LoperInputError(f"{source}: a TYPE 4 platform needs cal_matrix (6 x 6)")
            cal = tuple(map(tuple, _finite_array(self.cal_matrix, (6, 6), "cal_matrix", source).tolist()))
        elif self.cal_matrix is not None:
            raise LoperInputError(f"{source}: cal_matrix is for TYPE 4 platforms; this one is TYPE {kind}")
        object.__setattr__(self, "type", kind)
        object.__setattr__(self, "corners_m", tuple(map(tuple, corners.tolist())))
        object.__setattr__(self, "origin_m", tuple(origin.tolist()))
        object.__setattr__(self, "channels", tuple(channels))
        object.__setattr__(self, "cal_matrix", cal)

    @classmethod
    def from_mapping(cls, plate: Mapping) -> ForcePlatform:
        """A platform from a mapping with the C3D names ``TYPE``, ``CORNERS`` (m), ``ORIGIN`` (m), ``CHANNEL``
        and, for TYPE 4, ``CAL_MATRIX`` (or with the attribute names)."""
        keys = {str(k).upper(): v for k, v in plate.items()}
        names = {
            "TYPE": "TYPE",
            "CORNERS": "CORNERS_M",
            "ORIGIN": "ORIGIN_M",
            "CHANNEL": "CHANNELS",
            "CAL_MATRIX": "CAL_MATRIX",
        }
        values = {}
        for c3d_name, attribute in names.items():
            for key in (c3d_name, attribute):
                if key in keys:
                    values[attribute.lower()] = keys[key]
        missing = [n for n, a in names.items() if a.lower() not in values and n != "CAL_MATRIX"]
        if missing:
            raise LoperInputError(f"force platform: missing {', '.join(missing)} (given: {', '.join(keys)})")
        return cls(**values)


def _finite_array(values, shape: tuple[int, ...], name: str, source: str) -> np.ndarray:
    try:
        a = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise LoperInputError(f"{source}: {name} must be numbers of shape {shape}, got {values!r}") from None
    if a.shape != shape or not np.all(np.isfinite(a)):
        raise LoperInputError(f"{source}: {name} must be finite numbers of shape {shape}, got {a.tolist()!r}")
    return a


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
    """ezc3d analogs (1, n_channels, n_samples) from (n_samples, n_channels); refuses wrong shapes and non-finite
    values."""
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


def _extras_payload(
    first_frame, force_platforms, analog_scales, analog_offsets, events, n_ch: int, units_per_m: float, source: str
) -> dict[str, np.ndarray]:
    """Payload entries of the keyword-only extras of :func:`write_c3d` (checked)."""
    first = integer("first_frame", first_frame, source, minimum=0)
    if first > _MAX_FIRST_FRAME:
        raise LoperInputError(f"{source}: first_frame must be at most {_MAX_FIRST_FRAME}, got {first}")
    scales = np.ones(n_ch) if analog_scales is None else np.asarray(analog_scales, dtype=float).ravel()
    with np.errstate(over="ignore"):
        scales = scales.astype(np.float32).astype(float)  # the file holds float32 scales; readers use those
    if scales.shape != (n_ch,) or not np.all(np.isfinite(scales)) or np.any(scales == 0):
        raise LoperInputError(f"{source}: analog_scales must be {n_ch} finite, non-zero numbers, got {analog_scales!r}")
    offsets = (
        np.zeros(n_ch, dtype=np.int64)
        if analog_offsets is None
        else np.asarray([integer("analog_offsets", v, source, minimum=0) for v in analog_offsets], dtype=np.int64)
    )
    if offsets.shape != (n_ch,) or np.any(offsets > MAX_ANALOG_OFFSET):
        raise LoperInputError(
            f"{source}: analog_offsets must be {n_ch} integers in 0 .. {MAX_ANALOG_OFFSET}, got {analog_offsets!r}"
        )
    plates = [p if isinstance(p, ForcePlatform) else ForcePlatform.from_mapping(p) for p in force_platforms]
    for k, plate in enumerate(plates, start=1):
        beyond = [c for c in plate.channels if c > n_ch]
        if beyond:
            raise LoperInputError(f"{source}: force platform {k} uses channel(s) {beyond}; the file has {n_ch}")
    n_p = len(plates)
    cal = np.zeros((6, 6, n_p))
    for k, plate in enumerate(plates):
        cal[:, :, k] = np.eye(6) if plate.cal_matrix is None else np.asarray(plate.cal_matrix)
    contexts, labels, times = [], [], []
    for k, event in enumerate(events):
        try:
            context, label, time_s = event
        except (TypeError, ValueError):
            raise LoperInputError(f"{source}: events[{k}] must be (context, label, time_s), got {event!r}") from None
        if not isinstance(label, str) or not label.strip() or not isinstance(context, str):
            raise LoperInputError(f"{source}: events[{k}] needs a context and a non-empty label, got {event!r}")
        t = float(time_s) if isinstance(time_s, (int, float, np.floating, np.integer)) else np.nan
        if not np.isfinite(t) or t < 0:
            raise LoperInputError(f"{source}: events[{k}] time_s must be a finite number >= 0, got {time_s!r}")
        contexts.append(context.strip())
        labels.append(label.strip())
        times.append((np.floor(t / 60.0), t - 60.0 * np.floor(t / 60.0)))
    return {
        "first_frame": np.int64(first),
        "analog_scales": scales,
        "analog_offsets": offsets,
        "fp_type": np.array([p.type for p in plates], dtype=np.int64),
        "fp_corners": np.transpose(np.array([p.corners_m for p in plates]).reshape(n_p, 4, 3), (2, 1, 0)) * units_per_m,
        "fp_origin": np.array([p.origin_m for p in plates]).reshape(n_p, 3).T * units_per_m,
        "fp_channel": np.array([p.channels for p in plates], dtype=np.int64).reshape(n_p, 6).T,
        "fp_cal": cal,
        "event_contexts": np.array(contexts, dtype=str),
        "event_labels": np.array(labels, dtype=str),
        "event_times": np.array(times, dtype=float).reshape(len(times), 2).T,
    }


def _write_in_child(payload: dict[str, np.ndarray], out: Path, source: str) -> None:
    """Write ``out`` with ezc3d in a fresh Python process (see :func:`write_c3d`, Notes)."""
    payload_path = out.with_name(out.name + ".payload.npz")
    np.savez(payload_path, **payload)
    proc = subprocess.run(
        [sys.executable, "-m", "loper_analysis.io.ezc3d_child", str(payload_path), str(out)],
        capture_output=True,
        text=True,
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
    *,
    point_unit: str = "mm",
    first_frame: int = 0,
    force_platforms: Sequence[ForcePlatform | Mapping] = (),
    analog_scales: Sequence[float] | None = None,
    analog_offsets: Sequence[int] | None = None,
    events: Sequence[tuple[str, str, float]] = (),
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
    first_frame : int, keyword-only
        0-based number of the first frame (header word 4 holds ``first_frame +
        1``), 0 .. 65534; frame ``k`` is then at ``(first_frame + k) /
        point_rate_hz`` s (:attr:`C3DRecording.time_s`).
    force_platforms : sequence of ForcePlatform or mapping, keyword-only
        Written as the ``FORCE_PLATFORM`` group (``USED``, ``TYPE``, ``ZERO`` =
        (0, 0): no baseline correction, ``CORNERS`` and ``ORIGIN`` in the point
        unit, ``CHANNEL``, ``CAL_MATRIX`` (6, 6, n), the identity for TYPE 2).
        The platforms' channels must exist; their moment channels must be in N
        times the point unit (N·mm for ``"mm"``), as readers assume.
    analog_scales, analog_offsets : sequence, keyword-only
        Per-channel ``ANALOG:SCALE`` (finite, non-zero) and ``ANALOG:OFFSET``
        (integers 0 .. :data:`MAX_ANALOG_OFFSET`); default 1 and 0. The file
        holds the scales as float32 (``s32``), and ``analogs`` are the values
        in the channels' units: the file stores ``analogs / s32 + offset`` as
        float32 and readers return ``(stored - offset) * s32``
        (``ANALOG:GEN_SCALE`` is 1; ezc3d 1.7 takes the difference in
        float32): analogs made that way from float32 stored values come back
        exactly when the offset is 0 or the stored values are whole numbers
        (ADC counts). Offsets below 0 are refused:
        ezc3d 1.7 writes and reads ``|offset|``, unlike the C3D formula.
    events : sequence of (context, label, time_s), keyword-only
        The ``EVENT`` group (``USED``, ``CONTEXTS``, ``LABELS``,
        ``DESCRIPTIONS``, ``SUBJECTS``, ``ICON_IDS``, ``GENERIC_FLAGS``,
        ``TIMES`` (2, n) as whole minutes and seconds); times on the file's
        clock, the clock of :attr:`C3DRecording.time_s` (s, >= 0).

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

    With any keyword-only extra the child builds the file with ezc3d's
    low-level API (its Python ``write`` leaves ``ANALOG:OFFSET`` out); without
    them it writes exactly as it always did.
    """
    path = Path(path)
    source = str(path)
    unit = str(point_unit).lower()
    if unit not in LENGTH_UNITS_PER_M:
        raise LoperInputError(
            f"{source}: point_unit must be one of {', '.join(LENGTH_UNITS_PER_M)}, got {point_unit!r}"
        )
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
    extras = (
        first_frame != 0
        or len(force_platforms)
        or analog_scales is not None
        or analog_offsets is not None
        or len(events)
    )
    if extras:
        payload.update(
            _extras_payload(
                first_frame,
                force_platforms,
                analog_scales,
                analog_offsets,
                events,
                n_ch,
                LENGTH_UNITS_PER_M[unit],
                source,
            )
        )
        if n_ch:
            stored = samples / payload["analog_scales"][None, :, None] + payload["analog_offsets"][None, :, None]
            _analogs_for_file(stored[0].T, n_ch, samples.shape[2], f"{source} (stored as analogs / scale + offset)")
    with staged(path, "C3D file") as tmp:
        _write_in_child(payload, tmp, source)
    return path


def write_recording(path: str | os.PathLike, recording: C3DRecording, point_unit: str = "mm", **extras) -> Path:
    """Write a :class:`~loper_analysis.io.c3d.C3DRecording` (markers, analogs, first frame) with :func:`write_c3d`.

    ``extras`` are :func:`write_c3d`'s keyword-only arguments but ``first_frame``
    (``force_platforms``, ``analog_scales``, ``analog_offsets``, ``events``).
    """
    return write_c3d(
        path,
        recording.marker_labels,
        recording.markers_m,
        recording.point_rate_hz,
        recording.analog_labels,
        recording.analogs if recording.analog_labels else None,
        recording.analog_units,
        recording.analog_rate_hz,
        point_unit=point_unit,
        first_frame=recording.first_frame,
        **extras,
    )
