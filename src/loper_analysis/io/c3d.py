"""C3D motion-capture files: reading with ``ezc3d``.

Inside the library markers are in metres, shape (n_frames, n_markers, 3),
NaN where a marker is missing; analog channels are (n_samples, n_channels)
in each channel's own unit (``ANALOG:UNITS``), sampled at an integer multiple
of the point rate.

Reading (:func:`read_c3d`)
    * The point unit comes from ``POINT:UNITS`` (``mm``, ``cm`` or ``m``, case
      insensitive); a file with markers but no or an unknown unit is refused.
    * A point is missing (NaN) if ezc3d returns NaN for it (ezc3d 1.7 does so
      for every point whose stored residual is negative), if its residual is
      negative, or if all three coordinates are exactly 0 (the convention of
      writers that ignore residuals). Residuals are not trusted beyond their
      sign (ezc3d #386); a real marker exactly at the lab origin is therefore
      read as missing.
    * ``LABELS``, ``LABELS2``, ... are joined (ezc3d splits more than 255
      labels over several parameters).
    * Only markers are markers: the outputs of a lab's models stored as
      points (Plug-in Gait's angles, forces, moments, powers, segment points,
      modelled markers) and unlabelled points are kept apart, as they are in
      the file (:mod:`loper_analysis.io.c3d_points`); a point of theirs is
      missing where it is not finite or its residual is negative.
    * The numeric parameters of the ``PROCESSING`` group (Nexus writes
      ``Bodymass`` in kg and ``Height`` in mm there) are kept as read.
    * Labels and units are decoded as UTF-8, or as Latin-1 when they are not
      valid UTF-8 (:func:`~loper_analysis.io.c3d_parameters.decode_text`).
    * Events come from ``EVENT:CONTEXTS/LABELS/TIMES``
      (:func:`~loper_analysis.io.c3d_parameters.read_events`), times on the
      frames' clock: frame ``k`` of the array is at
      ``(first_frame + k) / POINT:RATE``.
    * Analog values are ezc3d's, i.e. after its SCALE/OFFSET handling.
      ``ANALOG:RATE`` must be an integer multiple of ``POINT:RATE``, and that
      multiple must equal the analog samples per frame of the raw header
      (word 10, which describes the data block); ``POINT:RATE`` must equal
      the header's frame rate (words 11-12).
    * Files of all three processor types of the standard are read: Intel and
      DEC by ezc3d, MIPS (SGI, big-endian) through its Intel twin
      (:mod:`loper_analysis.io.c3d_byte_order`).
    * ezc3d accepts some damaged files silently (a file cut inside its
      parameter section comes back with garbage frames, one cut inside its
      data with fewer frames and a header lowered to match), so the file
      size and the frame count are checked here against the raw header;
      ezc3d's own exceptions are wrapped.
    * ezc3d reads the data block in the storage format ``POINT:SCALE``
      declares (negative: 4-byte floats, positive: 16-bit integers) whatever
      its size. A file whose bytes after ``POINT:DATA_START`` fit the other
      format (about twice or half the declared size) and not the declared
      one, allowing for padding to the 512-byte block end and one spare
      block, is refused naming ``POINT:SCALE`` (zero bytes after declared
      integer data are taken for padding).

Writing is :func:`loper_analysis.io.c3d_writer.write_c3d`.

Every problem raises :class:`~loper_analysis.errors.LoperInputError` whose
message names the file and the field (``GROUP:PARAMETER``) or argument.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_byte_order import ezc3d_readable
from loper_analysis.io.c3d_layout import check_complete, check_rates, check_zeroed_tail
from loper_analysis.io.c3d_parameters import (
    EVENT_COLUMNS,
    param_float,
    param_strings,
    param_value,
    read_events,
)
from loper_analysis.io.c3d_points import MARKER, point_kinds, point_units
from loper_analysis.timing import library_import, timed_io

__all__ = [
    "LENGTH_UNITS_PER_M",
    "NEWTONS_PER_FORCE_UNIT",
    "C3DRecording",
    "rate_ratio",
    "read_c3d",
]

#: Length units accepted in files, as the number of units per metre.
LENGTH_UNITS_PER_M: dict[str, float] = {"mm": 1000.0, "cm": 100.0, "m": 1.0}
#: Newtons per unit of a force channel's ``ANALOG:UNITS`` (an empty unit is taken for N).
NEWTONS_PER_FORCE_UNIT: dict[str, float] = {"": 1.0, "N": 1.0, "n": 1.0, "kN": 1000.0, "KN": 1000.0, "kn": 1000.0}

#: Relative tolerance of the integer analog/point rate ratio.
_RATIO_TOLERANCE = 1e-6


@dataclass
class C3DRecording:
    """Markers and analog channels of one C3D file, in SI units.

    Attributes
    ----------
    source : str
        Path of the file read (used in error messages).
    marker_labels : list of str
        One label per marker, in file order.
    markers_m : numpy.ndarray
        Shape (n_frames, n_markers, 3), metres, lab frame; NaN where missing.
    point_rate_hz : float
        Frame rate of the markers (Hz).
    first_frame : int
        0-based frame number of the first frame (C3D header word 4 minus 1).
    analog_labels, analog_units : list of str
        One label and one unit per analog channel ("" when the file has no unit).
    analogs : numpy.ndarray
        Shape (n_samples, n_channels) with n_samples = n_frames * ratio, in
        each channel's unit; (n_frames, 0) when the file has no analogs.
    analog_rate_hz : float
        Analog sample rate (Hz), ``ratio * point_rate_hz`` with an integer
        ratio >= 1; equals ``point_rate_hz`` when there are no analogs.
    events : pandas.DataFrame
        The file's events, columns ``context``, ``label`` (str) and
        ``time_s`` (s, on the clock of :attr:`time_s`); empty by default.
    n_force_platforms : int
        ``FORCE_PLATFORM:USED`` (0 without platforms); the platforms
        themselves are read by :mod:`loper_analysis.io.force_platforms`.
    output_labels, output_kinds : list of str
        The points that are not markers (a lab's model outputs, segment and
        unlabelled points) and the kind of each
        (:func:`loper_analysis.io.c3d_points.point_kinds`: ``ANGLES``, ...).
    outputs : numpy.ndarray
        Shape (n_frames, n_outputs, 3), as stored (each kind in its unit:
        ``output_units``), NaN where missing.
    output_units : dict
        Kind -> unit as the file declares it (``{"ANGLES": "deg"}``).
    processing : dict
        Numeric parameters of the ``PROCESSING`` group, first value of each,
        as stored (Nexus: ``Bodymass`` kg, ``Height`` mm); empty without the group.
    """

    source: str
    marker_labels: list[str]
    markers_m: np.ndarray
    point_rate_hz: float
    first_frame: int = 0
    analog_labels: list[str] = field(default_factory=list)
    analog_units: list[str] = field(default_factory=list)
    analogs: np.ndarray | None = None
    analog_rate_hz: float | None = None
    events: pd.DataFrame = field(default_factory=lambda: _no_events())
    n_force_platforms: int = 0
    output_labels: list[str] = field(default_factory=list)
    output_kinds: list[str] = field(default_factory=list)
    outputs: np.ndarray | None = None
    output_units: dict[str, str] = field(default_factory=dict)
    processing: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.markers_m = np.asarray(self.markers_m, dtype=float)
        X = self.markers_m
        if X.ndim != 3 or X.shape[2] != 3 or X.shape[1] != len(self.marker_labels):
            raise LoperInputError(
                f"{self.source}: markers_m must have shape (n_frames, n_markers={len(self.marker_labels)}, 3), "
                f"got {X.shape}"
            )
        if self.outputs is None:
            self.outputs = np.zeros((X.shape[0], 0, 3))
        self.outputs = np.asarray(self.outputs, dtype=float)
        n_out = len(self.output_labels)
        if self.outputs.shape != (X.shape[0], n_out, 3) or len(self.output_kinds) != n_out:
            raise LoperInputError(
                f"{self.source}: outputs must have shape (n_frames, n_outputs={n_out}, 3) with one kind per "
                f"output, got {self.outputs.shape} and {len(self.output_kinds)} kind(s)"
            )
        if not isinstance(self.events, pd.DataFrame) or list(self.events.columns) != list(EVENT_COLUMNS):
            raise LoperInputError(f"{self.source}: events must be a DataFrame with columns {list(EVENT_COLUMNS)}")
        if self.analog_rate_hz is None:
            self.analog_rate_hz = float(self.point_rate_hz)
        ratio = rate_ratio(self.point_rate_hz, self.analog_rate_hz, self.source)
        if self.analogs is None:
            self.analogs = np.zeros((X.shape[0] * ratio, 0))
        self.analogs = np.asarray(self.analogs, dtype=float)
        n_ch = len(self.analog_labels)
        if self.analogs.shape != (X.shape[0] * ratio, n_ch) or len(self.analog_units) != n_ch:
            raise LoperInputError(
                f"{self.source}: analogs must have shape (n_frames * {ratio} = {X.shape[0] * ratio}, "
                f"n_channels = {n_ch}) with one unit per channel, got {self.analogs.shape} and "
                f"{len(self.analog_units)} unit(s)"
            )

    @property
    def samples_per_frame(self) -> int:
        """Analog samples per marker frame (the integer rate ratio)."""
        return rate_ratio(self.point_rate_hz, self.analog_rate_hz, self.source)

    @property
    def time_s(self) -> np.ndarray:
        """Frame times (n_frames,) in s: ``(first_frame + arange(n_frames)) / point_rate_hz``."""
        return (self.first_frame + np.arange(self.markers_m.shape[0])) / float(self.point_rate_hz)

    @property
    def analog_time_s(self) -> np.ndarray:
        """Analog sample times (n_samples,) in s; sample ``f * samples_per_frame`` is at frame ``f``'s time."""
        ratio = self.samples_per_frame
        return (self.first_frame * ratio + np.arange(self.analogs.shape[0])) / float(self.analog_rate_hz)

    def analog(self, label: str) -> np.ndarray:
        """One analog channel (n_samples,), in its unit.

        Raises
        ------
        LoperInputError
            If no channel, or more than one, has this label; the message names
            the file, the label and the channels present.
        """
        hits = [i for i, lab in enumerate(self.analog_labels) if lab == label]
        if len(hits) != 1:
            problem = "no analog channel" if not hits else f"{len(hits)} analog channels"
            raise LoperInputError(
                f"{self.source}: {problem} '{label}'; channels present: {', '.join(self.analog_labels) or 'none'}"
            )
        return self.analogs[:, hits[0]].copy()

    def force_channel_n(self, label: str, setting: str) -> np.ndarray:
        """One analog channel that holds a force (n_samples,), in N: its ``ANALOG:UNITS`` converted
        (:data:`NEWTONS_PER_FORCE_UNIT`).

        Raises
        ------
        LoperInputError
            A unit that is not a force's (``mV``, ``V``: an uncalibrated channel), naming the file, the channel,
            the unit and ``setting`` (the config key that chose the channel).
        """
        values = self.analog(label)
        unit = self.analog_units[self.analog_labels.index(label)].strip() if self.analog_units else ""
        if unit not in NEWTONS_PER_FORCE_UNIT:
            raise LoperInputError(
                f"{self.source}: analog channel '{label}' ({setting}) is in '{unit}' (ANALOG:UNITS), not a force "
                f"unit ({', '.join(u for u in NEWTONS_PER_FORCE_UNIT if u)}): an uncalibrated channel? Export "
                "it in N"
            )
        return values * NEWTONS_PER_FORCE_UNIT[unit]


# ---------------------------------------------------------------- helpers


def _no_events() -> pd.DataFrame:
    """An empty event table (columns :data:`~loper_analysis.io.c3d_parameters.EVENT_COLUMNS`)."""
    return pd.DataFrame(
        {"context": pd.Series(dtype=object), "label": pd.Series(dtype=object), "time_s": pd.Series(dtype=float)}
    )


def rate_ratio(point_rate_hz: float, analog_rate_hz: float, source: str) -> int:
    """The integer ratio analog/point rate; refuses a non-integer one."""
    ratio = float(analog_rate_hz) / float(point_rate_hz)
    n = round(ratio)
    if n < 1 or abs(ratio - n) > _RATIO_TOLERANCE * ratio:
        raise LoperInputError(
            f"{source}: mismatched analog/point rates: ANALOG:RATE = {analog_rate_hz:g} Hz is not an integer "
            f"multiple of POINT:RATE = {point_rate_hz:g} Hz (ratio {ratio:.6g})"
        )
    return int(n)


def _labels_for(params, group: str, n: int, source: str) -> list[str]:
    labels = param_strings(params, group, "LABELS")
    if len(labels) < n:
        raise LoperInputError(f"{source}: {group}:LABELS holds {len(labels)} label(s) for {n} {group.lower()}s")
    return labels[:n]


def _point_units_per_m(params, source: str) -> float:
    units = param_strings(params, "POINT", "UNITS")
    if not units or not units[0]:
        raise LoperInputError(f"{source}: POINT:UNITS not declared; cannot tell whether markers are in mm, cm or m")
    unit = units[0].lower()
    if unit not in LENGTH_UNITS_PER_M:
        raise LoperInputError(
            f"{source}: unknown POINT:UNITS '{units[0]}'; expected one of {', '.join(LENGTH_UNITS_PER_M)}"
        )
    return LENGTH_UNITS_PER_M[unit]


def _open_c3d(path: Path):
    """ezc3d's reader with its exceptions turned into LoperInputError."""
    with library_import():
        import ezc3d

    source = str(path)
    if not path.exists():
        raise LoperInputError(f"{source}: C3D file not found")
    if not path.is_file():  # ezc3d does not return on a directory
        raise LoperInputError(f"{source}: not a regular file")
    try:
        with ezc3d_readable(path) as readable:  # a MIPS file through its Intel twin
            return ezc3d.c3d(str(readable))
    except LoperInputError:
        raise
    except Exception as exc:  # ezc3d raises OSError, RuntimeError, ValueError, ... for damaged files
        raise LoperInputError(
            f"{source}: not a readable C3D file (truncated, damaged or another format): {type(exc).__name__}: {exc}"
        ) from exc


def _points_from(c3d) -> tuple[np.ndarray, np.ndarray]:
    """Every point (n_frames, n_points, 3) as stored, and where ezc3d gives NaN or the residual is negative."""
    points = np.asarray(c3d["data"]["points"], dtype=float)[:3]  # (3, n_points, n_frames)
    X = np.transpose(points, (2, 1, 0))
    missing = ~np.all(np.isfinite(X), axis=2)
    residuals = np.asarray(c3d["data"]["meta_points"]["residuals"], dtype=float)
    if residuals.shape == (1, X.shape[1], X.shape[0]):
        missing |= residuals[0].T < 0
    return X, missing


def _markers_from(points: np.ndarray, missing: np.ndarray, units_per_m: float) -> np.ndarray:
    """(n_frames, n_markers, 3) in m, NaN where missing or at exactly (0, 0, 0)."""
    X = points / units_per_m
    X[missing | np.all(points == 0.0, axis=2)] = np.nan
    return X


def _processing(params) -> dict[str, float]:
    """First value of each numeric ``PROCESSING`` parameter."""
    out = {}
    for name, entry in (params.get("PROCESSING") or {}).items():
        try:
            value = np.asarray(entry["value"], dtype=float).ravel()
        except (TypeError, ValueError, KeyError):
            continue
        if value.size and np.isfinite(value[0]):
            out[str(name)] = float(value[0])
    return out


def _analogs_from(c3d, point_rate_hz: float, source: str) -> tuple[float, int, list[str], list[str], np.ndarray]:
    """Analog rate (Hz), samples per frame, labels, units and samples (n_samples, n_channels) of a read file.

    Without channels: the point rate, 1, [], [] and an empty (n_samples, 0) array.
    """
    analogs = np.asarray(c3d["data"]["analogs"], dtype=float)  # (1, n_channels, n_samples)
    if analogs.ndim != 3 or analogs.shape[1] == 0:
        n_samples = analogs.shape[2] if analogs.ndim == 3 else 0
        return point_rate_hz, 1, [], [], np.zeros((n_samples, 0))
    n_channels = analogs.shape[1]
    params = c3d["parameters"]
    rate = param_float(params, "ANALOG", "RATE", source)
    ratio = rate_ratio(point_rate_hz, rate, source)
    labels = _labels_for(params, "ANALOG", n_channels, source)
    units = (param_strings(params, "ANALOG", "UNITS") + [""] * n_channels)[:n_channels]
    return rate, ratio, labels, units, analogs[0].T.copy()


def _force_platforms_used(params) -> int:
    """``FORCE_PLATFORM:USED`` (0 when the group or the parameter is absent)."""
    used = param_value(params, "FORCE_PLATFORM", "USED")
    try:
        return max(int(np.asarray(used, dtype=float).ravel()[0]), 0)
    except (TypeError, ValueError, IndexError):
        return 0


# ---------------------------------------------------------------- reader


@timed_io
def read_c3d(path: str | os.PathLike) -> C3DRecording:
    """Read markers (converted to m) and analog channels of a C3D file.

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.

    Returns
    -------
    C3DRecording
        ``markers_m`` (n_frames, n_markers, 3) in m with NaN for missing
        points; ``analogs`` (n_frames * ratio, n_channels) in the channels'
        units; rates in Hz; ``first_frame`` 0-based; ``events`` (context,
        label, time_s).

    Raises
    ------
    LoperInputError
        Missing file; not a C3D file, damaged or truncated (ezc3d's exception
        is quoted); ``POINT:UNITS`` not declared or unknown (markers
        present); ``POINT:RATE`` missing or unlike the header's frame rate;
        too few labels; ``ANALOG:RATE`` not an integer multiple of
        ``POINT:RATE`` ("mismatched analog/point rates") or giving another
        number of samples per frame than the header (word 10) and the data
        block hold; ``ANALOG:USED`` unlike the header's analog values per
        frame (word 3); a data block the size of the other storage format
        than ``POINT:SCALE`` declares; malformed ``EVENT:TIMES``; last
        frames holding zero bytes only (an interrupted copy or export: the
        message names the first zeroed frame, its time and the zeroed
        share). The message names the file.
    """
    path = Path(path)
    return recording_from_ezc3d(_open_c3d(path), path)


def recording_from_ezc3d(c3d, path: str | os.PathLike) -> C3DRecording:
    """The :class:`C3DRecording` of a file ezc3d has read (``ezc3d.c3d(path)``), checked as :func:`read_c3d`
    says."""
    path = Path(path)
    source = str(path)
    params = c3d["parameters"]
    point_rate = param_float(params, "POINT", "RATE", source)
    n_points = int(np.shape(c3d["data"]["points"])[1])
    labels = _labels_for(params, "POINT", n_points, source)
    kinds = point_kinds(params, labels)
    is_marker = np.array([k == MARKER for k in kinds], dtype=bool)
    n_markers = int(is_marker.sum())
    units_per_m = _point_units_per_m(params, source) if n_markers else 1.0
    analog_rate, ratio, analog_labels, analog_units, samples = _analogs_from(c3d, point_rate, source)
    n_channels = samples.shape[1]
    check_rates(path, point_rate, analog_rate, ratio, n_channels)
    n_frames = int(np.shape(c3d["data"]["points"])[2]) if n_points else samples.shape[0] // ratio
    if n_channels and samples.shape[0] != n_frames * ratio:
        raise LoperInputError(
            f"{source}: {samples.shape[0]} analog samples for {n_frames} frames at {ratio} samples per frame"
        )
    check_complete(c3d, path, n_frames, 4 * n_points + n_channels * ratio)
    if n_points:  # an interrupted copy: the last frames zeroed (analog-only files are left as they are)
        check_zeroed_tail(c3d, path, n_frames, 4 * n_points + n_channels * ratio, point_rate, n_channels)
    if n_points:
        points, missing = _points_from(c3d)
    else:
        points, missing = np.zeros((n_frames, 0, 3)), np.zeros((n_frames, 0), dtype=bool)
    markers = _markers_from(points[:, is_marker], missing[:, is_marker], units_per_m)
    outputs = points[:, ~is_marker].copy()
    outputs[missing[:, ~is_marker]] = np.nan
    return C3DRecording(
        source=source,
        marker_labels=[lab for lab, m in zip(labels, is_marker) if m],
        markers_m=markers,
        point_rate_hz=point_rate,
        first_frame=int(c3d["header"]["points"]["first_frame"]),
        analog_labels=analog_labels,
        analog_units=analog_units,
        analogs=samples if n_channels else None,
        analog_rate_hz=analog_rate,
        events=read_events(params, source),
        n_force_platforms=_force_platforms_used(params),
        output_labels=[lab for lab, m in zip(labels, is_marker) if not m],
        output_kinds=[k for k in kinds if k != MARKER],
        outputs=outputs,
        output_units=point_units(params),
        processing=_processing(params),
    )
