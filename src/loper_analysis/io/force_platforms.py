"""Force platforms of a C3D file, read with ezc3d's platform extraction, in SI units and the lab frame.

What ezc3d returns (``ezc3d.c3d(path, extract_forceplat_data=True)``,
``["data"]["platform"]``; checked against OpenSim's reading of
``walking5.c3d`` in ``tests/io/test_force_platforms.py``):

* Channels are taken from ``FORCE_PLATFORM:CHANNEL`` (1-based analog channel
  numbers), never from their labels; TYPE 4 applies ``CAL_MATRIX``
  (``CAL_MATRIX[row, column, plate]``, ``[F; M] = CAL @ channels``), TYPE 3
  (Kistler, 8 channels) sums the sensor forces and builds the moments from
  ``ORIGIN``; TYPE 2 takes the six channels as they are. ``ANALOG:SCALE``,
  ``OFFSET`` and ``GEN_SCALE`` are applied by ezc3d's analog reader.
* The plate frame comes from the corners: x = corner 1 - corner 2, y =
  corner 1 - corner 4, z = x cross y (for the usual plate, z points down).
  Force and moment are rotated into the lab frame.
* The moment is about the centre of the top surface, the mean of the four
  corners: ezc3d moves the channel moment from the sensor origin with
  ``ORIGIN`` (whose sign it normalises so that the surface lies at negative
  plate z, i.e. above the sensor).
* Corner order: ezc3d's normalisation of ``ORIGIN`` puts the surface above
  the sensor only for a plate whose z axis points down, the usual corner
  order. A file may list the corners the other way round the plate (z up);
  its channels are then in that frame, and the surface lies at positive
  plate z. ezc3d still makes ``ORIGIN``'s z negative, i.e. moves the moment
  to a point below the sensor, so for such a plate the moment is corrected
  here: ``M = M_ezc3d - 2 F x (R o)``, with ``o`` ezc3d's ``ORIGIN`` (TYPE 3:
  only its z, the one ezc3d moves the moment by) and ``R`` the plate frame.
  "Up" is the lab's up direction ``up`` (lab +Z unless given): a plate
  frame whose z axis has a positive component along ``up`` points up. The
  usual corner order gives the moment exactly as ezc3d does.
* Units: force in ``FORCE_PLATFORM:UNITS`` (N when absent), corners and
  positions in ``POINT:UNITS``, moments in force unit x position unit
  (N·mm for a file in mm). Converted here to N, m and N·m.
* Sign: the force is the one the plate exerts on the body (ground reaction):
  its vertical component (along the lab's up, +Z in a Z-up lab) is positive
  while someone stands on the plate (walking5: +480 N in stance, channel
  ``Fz1`` = -480 N in the plate's downward z). No sign is changed here.
* Times: sample k of the analogs is at ``first_frame / point_rate + k /
  analog_rate``, with ezc3d's 0-based ``first_frame``.

Checks beyond ezc3d's (which reads these files without a complaint):

* ``CAL_MATRIX`` of a plate whose TYPE ezc3d applies it to
  (:data:`CALIBRATED_TYPES`, TYPE 4): declared, of shape (6, 6, n), finite,
  without an all-zero row or column, without two equal columns, and of full
  rank 6 (singular values above :data:`CAL_RTOL` times the largest). A
  singular matrix reads a load as 0 (a zero ``Fz`` row gives no vertical
  force and no gait event). ezc3d 1.7 ignores ``CAL_MATRIX`` for TYPE 2
  and 3, so theirs is not checked.
* Corners listed in the other order than the frame of the channels: the
  force then points down while someone stands on the plate. A level plate
  whose vertical force reaches :data:`DOWNWARD_LOAD_N` downward while never
  :data:`MAX_UPWARD_REST_N` upward is refused naming
  ``FORCE_PLATFORM:CORNERS``, the plate, its corners and the z axis they
  give. Plates whose channels are in the frame of their corners pass either
  way round.

Supported TYPEs are 2, 3 and 4; others (1, 5, 6, 7, 11, 12, 21, ...) are
refused. Every problem raises :class:`~loper_analysis.errors.LoperInputError`
naming the file, the field and the value.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from loper_analysis.constants import LAB_Z_UP
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import LENGTH_UNITS_PER_M, C3DRecording, read_c3d, recording_from_ezc3d
from loper_analysis.io.c3d_byte_order import ezc3d_readable
from loper_analysis.timing import library_import, timed_io

__all__ = [
    "CALIBRATED_TYPES",
    "CAL_RTOL",
    "DOWNWARD_LOAD_N",
    "MAX_UPWARD_REST_N",
    "SUPPORTED_TYPES",
    "ForcePlatform",
    "count_force_platforms",
    "platforms_from_ezc3d",
    "read_c3d_with_platforms",
    "read_force_platforms",
]

#: FORCE_PLATFORM:TYPE values read; the number of analog channels each uses.
SUPPORTED_TYPES: dict[int, int] = {2: 6, 3: 8, 4: 6}

#: Moment units recognised in ``ANALOG:UNITS`` (spelling normalised), as N·m per unit.
_MOMENT_UNITS: dict[str, float] = {"nmm": 1e-3, "ncm": 1e-2, "nm": 1.0}

#: FORCE_PLATFORM:TYPE values whose ``CAL_MATRIX`` ezc3d applies (6 x 6, ``[F; M] = CAL @ channels``).
#: ezc3d 1.7 reads TYPE 2 and TYPE 3 plates without it: their CAL_MATRIX, often zeros, is not checked.
CALIBRATED_TYPES: frozenset[int] = frozenset({4})
#: Smallest ratio of a calibration matrix's smallest to largest singular value (reciprocal of the largest
#: condition number): a real plate's matrix (force rows in N/V, moment rows in N·mm/V) stays near 1e-3.
CAL_RTOL = 1e-8
#: Outputs of a 6 x 6 calibration matrix, by row.
_CAL_OUTPUTS = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")

#: A plate's vertical force (N, along the lab's up) whose 1st percentile lies below ``-DOWNWARD_LOAD_N``
#: while its 99th percentile stays below ``MAX_UPWARD_REST_N`` points down while loaded (read_force_platforms).
DOWNWARD_LOAD_N = 200.0
#: See :data:`DOWNWARD_LOAD_N`: the largest upward reading of a plate that carries no upward load, N.
MAX_UPWARD_REST_N = 100.0
#: Plates whose normal lies within this angle (deg) of the lab's up or down are checked for a downward force.
_LEVEL_DEG = 45.0


@dataclass(frozen=True)
class ForcePlatform:
    """One force platform: the ground reaction on the body and the plate's geometry, lab frame, SI units.

    Attributes
    ----------
    number : int
        Plate number, 1-based (order of ``FORCE_PLATFORM`` entries).
    type : int
        ``FORCE_PLATFORM:TYPE`` (2, 3 or 4).
    channels : tuple of int
        The 1-based analog channels of ``FORCE_PLATFORM:CHANNEL`` used (6 or 8).
    analog_rate_hz : float
        Sample rate of the force and moment (Hz).
    time_s : numpy.ndarray
        Shape (n_samples,), s: ``first_frame / point_rate + k / analog_rate``.
    force_n : numpy.ndarray
        Shape (n_samples, 3), N, lab frame: force the plate exerts on the body
        (vertical component positive while loaded), resting level included.
    moment_nm : numpy.ndarray
        Shape (n_samples, 3), N·m, lab frame: moment of that force about
        :attr:`centre_m`, resting level included (corrected for a plate whose
        corners are listed the other way round, see the module notes).
    corners_m : numpy.ndarray
        Shape (4, 3), m, lab frame, in ``FORCE_PLATFORM:CORNERS`` order.
    centre_m : numpy.ndarray
        Shape (3,), m, lab frame: centre of the top surface (mean of the corners),
        the point the moment is about.
    source : str
        The file read (for messages).
    """

    number: int
    type: int
    channels: tuple[int, ...]
    analog_rate_hz: float
    time_s: np.ndarray
    force_n: np.ndarray
    moment_nm: np.ndarray
    corners_m: np.ndarray
    centre_m: np.ndarray
    source: str = ""


def _value(params, name: str):
    """``FORCE_PLATFORM:name`` value as an array, or None when absent."""
    try:
        return np.asarray(params["FORCE_PLATFORM"][name]["value"])
    except KeyError:
        return None


def _used(params) -> int:
    used = _value(params, "USED")
    if used is None or used.size == 0:
        return 0
    return int(np.ravel(used)[0])


def _open(path: Path, extract: bool):
    with library_import():
        import ezc3d

    source = str(path)
    if not path.is_file():
        raise LoperInputError(f"{source}: C3D file not found" if not path.exists() else f"{source}: not a regular file")
    try:
        with ezc3d_readable(path) as readable:  # a MIPS file through its Intel twin
            return ezc3d.c3d(str(readable), extract_forceplat_data=extract)
    except LoperInputError:
        raise
    except Exception as exc:  # ezc3d raises RuntimeError, ValueError, ... for damaged files and bad parameters
        return exc


def count_force_platforms(path: str | os.PathLike) -> int:
    """``FORCE_PLATFORM:USED`` of a C3D file; 0 when the group or the parameter is absent.

    Raises
    ------
    LoperInputError
        Missing or unreadable file.
    """
    path = Path(path)
    c3d = _open(path, extract=False)
    if isinstance(c3d, Exception):
        raise LoperInputError(f"{path}: not a readable C3D file: {type(c3d).__name__}: {c3d}") from c3d
    return _used(c3d["parameters"])


def _check_parameters(params, n_analogs: int, source: str) -> tuple[int, list[int], list[tuple[int, ...]]]:
    """USED, TYPEs and CHANNEL entries of every plate; refuses what ezc3d cannot (or should not) read."""
    used = _used(params)
    if used <= 0:
        value = "absent" if _value(params, "USED") is None else f"= {used}"
        raise LoperInputError(f"{source}: FORCE_PLATFORM:USED {value}: the file holds no force platforms")
    types = _value(params, "TYPE")
    channel = _value(params, "CHANNEL")
    for name, value in (
        ("TYPE", types),
        ("CHANNEL", channel),
        ("CORNERS", _value(params, "CORNERS")),
        ("ORIGIN", _value(params, "ORIGIN")),
    ):
        if value is None or value.size == 0:
            raise LoperInputError(f"{source}: FORCE_PLATFORM:{name} not declared for {used} force platform(s)")
    types = np.ravel(types).astype(int)
    if types.size < used:
        raise LoperInputError(f"{source}: FORCE_PLATFORM:TYPE holds {types.size} value(s) for USED = {used} platforms")
    channel = channel.reshape(channel.shape[0], -1) if channel.ndim >= 2 else channel.reshape(-1, 1)
    plate_channels = []
    for k in range(used):
        kind = int(types[k])
        if kind not in SUPPORTED_TYPES:
            raise LoperInputError(
                f"{source}: FORCE_PLATFORM:TYPE of platform {k + 1} is {kind}; supported types are "
                f"{', '.join(map(str, SUPPORTED_TYPES))}"
            )
        n = SUPPORTED_TYPES[kind]
        if channel.shape[0] < n or channel.shape[1] <= k:
            raise LoperInputError(
                f"{source}: FORCE_PLATFORM:CHANNEL has shape {channel.shape}; platform {k + 1} (TYPE {kind}) needs {n} "
                "channel numbers"
            )
        chans = tuple(int(c) for c in channel[:n, k])
        bad = [c for c in chans if not 1 <= c <= n_analogs]
        if bad:
            raise LoperInputError(
                f"{source}: FORCE_PLATFORM:CHANNEL of platform {k + 1} = {list(chans)} points at analog channel(s) "
                f"{bad}, but the file has {n_analogs} analog channel(s)"
            )
        plate_channels.append(chans)
    _check_calibration(params, [int(t) for t in types[:used]], source)
    return used, [int(t) for t in types[:used]], plate_channels


def _format_matrix(cal: np.ndarray) -> str:
    """A 6 x 6 matrix as rows of 4 significant digits, for messages."""
    return "[" + ", ".join("[" + ", ".join(f"{v:.4g}" for v in row) + "]" for row in cal) + "]"


def _calibration_problems(cal: np.ndarray) -> list[str]:
    """What makes a 6 x 6 calibration matrix unusable (empty when it is usable).

    Parameters
    ----------
    cal : numpy.ndarray
        Shape (6, 6): ``[F; M] = cal @ channels`` (row = output Fx .. Mz, column = channel).

    Returns
    -------
    list of str
        Non-finite entries; all-zero rows (an output that reads 0 whatever
        the load) and columns (a channel that is ignored); equal columns
        (two channels read as one); a rank below 6, the rank counted with
        the relative tolerance :data:`CAL_RTOL` on the singular values.
    """
    cal = np.asarray(cal, dtype=float)
    if not np.all(np.isfinite(cal)):
        where = [tuple(int(i) + 1 for i in ij) for ij in np.argwhere(~np.isfinite(cal))]
        return [f"non-finite entries at (row, column) {where}"]
    problems = []
    zero_rows = [i for i in range(6) if not np.any(cal[i])]
    zero_cols = [j for j in range(6) if not np.any(cal[:, j])]
    if zero_rows:
        problems.append("zero row(s) " + ", ".join(f"{i + 1} ({_CAL_OUTPUTS[i]})" for i in zero_rows))
    if zero_cols:
        problems.append("zero column(s) " + ", ".join(str(j + 1) for j in zero_cols))
    equal = [
        (i, j) for i in range(6) for j in range(i + 1, 6) if np.any(cal[:, i]) and np.array_equal(cal[:, i], cal[:, j])
    ]
    if equal:
        problems.append("equal columns " + ", ".join(f"{i + 1} and {j + 1}" for i, j in equal))
    singular = np.linalg.svd(cal, compute_uv=False)  # descending
    rank = int(np.count_nonzero(singular > CAL_RTOL * singular[0]))  # numpy's matrix_rank with a relative tolerance
    if rank < 6:
        cond = singular[0] / singular[-1] if singular[-1] > 0 else np.inf
        problems.insert(0, f"rank {rank} of 6 (condition number {cond:.3g}, at most {1.0 / CAL_RTOL:.0e})")
    return problems


def _check_calibration(params, types: list[int], source: str) -> None:
    """Refuse a missing, misshapen or singular ``FORCE_PLATFORM:CAL_MATRIX`` of a plate whose TYPE ezc3d applies
    it to (:data:`CALIBRATED_TYPES`): such a matrix zeroes or mixes the plate's outputs without a complaint."""
    plates = [k for k, kind in enumerate(types) if kind in CALIBRATED_TYPES]
    if not plates:
        return
    first = plates[0] + 1
    value = _value(params, "CAL_MATRIX")
    if value is None or value.size == 0:
        raise LoperInputError(
            f"{source}: FORCE_PLATFORM:CAL_MATRIX not declared; platform {first} is TYPE {types[first - 1]}, whose "
            "channels need a 6 x 6 calibration matrix"
        )
    if value.ndim < 2 or value.shape[:2] != (6, 6) or value.size < 36 * (plates[-1] + 1):
        raise LoperInputError(
            f"{source}: FORCE_PLATFORM:CAL_MATRIX has shape {value.shape}; platform {plates[-1] + 1} is TYPE "
            f"{types[plates[-1]]}, which needs one 6 x 6 matrix per platform: shape (6, 6, n), n >= {plates[-1] + 1}"
        )
    flat = np.asarray(value, dtype=float).ravel(order="F")  # file order: row fastest, then column, then plate
    for k in plates:
        cal = flat[36 * k : 36 * (k + 1)].reshape(6, 6, order="F")
        problems = _calibration_problems(cal)
        if problems:
            raise LoperInputError(
                f"{source}: FORCE_PLATFORM:CAL_MATRIX of platform {k + 1} (TYPE {types[k]}) is unusable: "
                f"{'; '.join(problems)}; [F; M] = CAL_MATRIX @ channels would read a load as 0 or mix channels. "
                f"CAL_MATRIX[:, :, {k + 1}] = {_format_matrix(cal)}"
            )


def _moment_unit_check(params, plate: int, chans: tuple[int, ...], kind: int, expected_nm: float, source: str) -> None:
    """Refuse moment channels whose declared unit differs from the one ezc3d assumes (force x position unit)."""
    if kind == 3:
        return
    try:
        units = [str(u).strip() for u in params["ANALOG"]["UNITS"]["value"]]
    except KeyError:
        return
    for c in chans[3:6]:
        if c - 1 >= len(units):
            continue
        key = re.sub(r"[\s.·*_-]", "", units[c - 1]).lower()
        if key in _MOMENT_UNITS and not np.isclose(_MOMENT_UNITS[key], expected_nm):
            raise LoperInputError(
                f"{source}: ANALOG:UNITS of channel {c} (a moment of platform {plate}) is '{units[c - 1]}', but "
                f"POINT:UNITS makes ezc3d expect N·m x {expected_nm:g}; the moments cannot be placed consistently"
            )


def _plate_frame(corners: np.ndarray) -> np.ndarray:
    """ezc3d's plate frame (3, 3), columns x, y, z in the lab: x = corner 1 - corner 2, y = corner 1 - corner 4
    made orthogonal, z = x cross y."""
    x = corners[0] - corners[1]
    z = np.cross(x, corners[0] - corners[3])
    y = np.cross(z, x)
    return np.column_stack([v / np.linalg.norm(v) for v in (x, y, z)])


def _check_force_direction(
    force_n: np.ndarray,
    z_axis: np.ndarray,
    up: np.ndarray,
    corners: np.ndarray,
    unit: str,
    plate: tuple[int, Sequence[int]],
    source: str,
) -> None:
    """Refuse a level plate whose vertical force points down while loaded, naming its corners and their z axis.

    Channels are in the plate frame that ``FORCE_PLATFORM:CORNERS`` defines
    (z = (corner 1 - corner 2) x (corner 1 - corner 4)); either corner order
    is read (module notes) as long as the channels are in that frame. Corners
    listed in the other order than the channels' frame flip the force: the
    ground reaction then points down while someone stands on the plate. So
    does a file whose channels hold the force on the plate. Refused when the
    vertical force ``force_n . up`` reaches ``-DOWNWARD_LOAD_N`` (1st
    percentile) and stays below ``MAX_UPWARD_REST_N`` (99th percentile), for
    a plate within 45 deg of level (one that ``up`` does not make a wall).

    Parameters
    ----------
    force_n : numpy.ndarray
        Shape (n, 3), N, lab frame, as read.
    z_axis : numpy.ndarray
        Shape (3,): the plate's z axis from the corners (unit, lab frame).
    up : numpy.ndarray
        Shape (3,): the lab's up direction (unit, lab frame).
    corners : numpy.ndarray
        Shape (4, 3): ``FORCE_PLATFORM:CORNERS`` as stored, in ``unit``.
    unit : str
        ``POINT:UNITS`` (the corners' unit).
    plate : (int, sequence of int)
        Plate number, 1-based, and its analog channels (1-based).
    source : str
        The file (for messages).

    A vertical force that never comes near zero (its 99th percentile below ``-DOWNWARD_LOAD_N``) is an offset
    under every sample, not a flipped load: refused as such, naming the plate's channels.
    """
    plate, channels = plate
    facing = float(z_axis @ up)
    if force_n.shape[0] == 0 or abs(facing) < np.cos(np.radians(_LEVEL_DEG)):
        return
    vertical = force_n @ up
    low, high = (float(v) for v in np.percentile(vertical, [1.0, 99.0]))
    if not (low <= -DOWNWARD_LOAD_N and high < MAX_UPWARD_REST_N):
        return
    if high < -DOWNWARD_LOAD_N:  # never near zero: an offset under every sample rather than a flipped load
        steady = high - low < DOWNWARD_LOAD_N
        also = (
            f"; or someone stood on it throughout while FORCE_PLATFORM:CORNERS lists its corners the other way "
            f"round the frame of its channels (z axis {np.round(z_axis, 3).tolist()})"
            if steady
            else ""
        )
        raise LoperInputError(
            f"{source}: platform {plate}: its vertical force (along up {np.round(up, 3).tolist()}) never comes near "
            f"zero: {high:.1f} N or less throughout (99th percentile), {low:.1f} N at the 1st: an offset of about "
            f"{-low:.0f} N under every sample (the plate not zeroed before the trial, or the ANALOG:OFFSET of its "
            f"channels {list(channels)}){also}; zero the plate, or export the trial again"
        )
    listed = [[float(f"{v:.6g}") for v in corner] for corner in corners]
    reading = (
        f"its vertical force (along up {np.round(up, 3).tolist()}) points down while loaded: {low:.1f} N at "
        f"the 1st percentile, at most {high:.1f} N at the 99th"
    )
    if facing > 0:
        cause = (
            f"pointing up: the corners are listed the other way round the plate (reversed or permuted) from "
            f"the frame of its channels, so {reading}; list them in the order of the channels' frame (the "
            "usual order gives a z axis pointing down)"
        )
    else:
        cause = (
            f"pointing down (the usual order), yet {reading}: the channels are in the frame of the corners "
            "listed the other way round (the corners were reversed or permuted), or hold the force on the "
            "plate instead of on the body"
        )
    raise LoperInputError(
        f"{source}: FORCE_PLATFORM:CORNERS of platform {plate} = {listed} {unit} give a plate z axis "
        f"{np.round(z_axis, 3).tolist()} (lab frame, (corner 1 - corner 2) x (corner 1 - corner 4)), {cause}"
    )


def _lab_up(up: Sequence[float] | None, source: str) -> np.ndarray:
    """``up`` as a unit vector (3,); lab +Z for None."""
    u = np.asarray(LAB_Z_UP if up is None else up, dtype=float)
    norm = float(np.linalg.norm(u)) if u.shape == (3,) and np.all(np.isfinite(u)) else 0.0
    if norm == 0.0:
        raise LoperInputError(f"{source}: up must be 3 finite numbers, not all 0 (a direction, lab frame), got {up!r}")
    return u / norm


def read_force_platforms(path: str | os.PathLike, up: Sequence[float] | None = None) -> list[ForcePlatform]:
    """Every force platform of a C3D file, in file order.

    Parameters
    ----------
    path : str or path-like
        The ``.c3d`` file.
    up : array_like, optional
        Shape (3,): the lab's up direction, lab frame (normalised here); None:
        lab +Z (:data:`loper_analysis.constants.LAB_Z_UP`). It decides which
        plates list their corners the other way round (module notes).

    Returns
    -------
    list of ForcePlatform
        One per plate (``FORCE_PLATFORM:USED`` of them), numbered from 1;
        forces in N, moments in N·m about the surface centre, corners in m,
        all in the lab frame (see the module notes for the conventions).

    Raises
    ------
    LoperInputError
        Missing or unreadable file; ``FORCE_PLATFORM:USED`` absent or 0 (the
        file holds no platforms: use :func:`count_force_platforms` to test
        first); TYPE not 2, 3 or 4; ``FORCE_PLATFORM:CHANNEL`` pointing at
        analog channels that do not exist; a missing, misshapen or unusable
        ``FORCE_PLATFORM:CAL_MATRIX`` of a TYPE 4 plate (non-finite, a zero
        row or column, equal columns, rank below 6); ``POINT:UNITS`` or
        ``FORCE_PLATFORM:UNITS`` unknown; moment channels whose unit
        disagrees with ``POINT:UNITS``; a level plate whose force points down
        while loaded (``FORCE_PLATFORM:CORNERS`` in the other order than the
        channels' frame, or the force on the plate); ezc3d's own refusal
        (quoted); a bad ``up``.
    """
    path = Path(path)
    source = str(path)
    lab_up = _lab_up(up, source)
    c3d = _open(path, extract=True)
    failure = c3d if isinstance(c3d, Exception) else None
    if failure is not None:
        c3d = _open(path, extract=False)  # diagnose the parameters ezc3d's extraction refused
        if isinstance(c3d, Exception):
            raise LoperInputError(f"{source}: not a readable C3D file: {type(c3d).__name__}: {c3d}") from c3d
    return platforms_from_ezc3d(c3d, path, lab_up, failure)


@timed_io
def read_c3d_with_platforms(
    path: str | os.PathLike, up: Sequence[float] | None = None
) -> tuple[C3DRecording, list[ForcePlatform]]:
    """A C3D file's recording (:func:`loper_analysis.io.c3d.read_c3d`) and its force platforms
    (:func:`read_force_platforms`; none when ``FORCE_PLATFORM:USED`` is 0 or absent), from one reading of the
    file. A file whose platforms ezc3d cannot extract is read again to name the cause, as those two say."""
    path = Path(path)
    c3d = _open(path, extract=True)
    if isinstance(c3d, Exception):
        rec = read_c3d(path)  # its own refusals first, then the platforms'
        return rec, (read_force_platforms(path, up) if rec.n_force_platforms else [])
    rec = recording_from_ezc3d(c3d, path)
    return rec, (platforms_from_ezc3d(c3d, path, _lab_up(up, str(path))) if rec.n_force_platforms else [])


def platforms_from_ezc3d(c3d, path: str | os.PathLike, lab_up: np.ndarray, failure: Exception | None = None):
    """The force platforms of a file ezc3d has read with ``extract_forceplat_data=True`` (``failure``: the
    exception of that extraction, ``c3d`` then read without it to diagnose), as :func:`read_force_platforms`."""
    source = str(path)
    params = c3d["parameters"]
    n_analogs = int(np.shape(c3d["data"]["analogs"])[1])
    used, types, plate_channels = _check_parameters(params, n_analogs, source)
    if failure is not None:
        raise LoperInputError(
            f"{source}: ezc3d cannot extract the force platforms: {type(failure).__name__}: {failure}"
        ) from failure
    platforms = c3d["data"]["platform"]
    if len(platforms) != used:
        raise LoperInputError(
            f"{source}: ezc3d extracted {len(platforms)} platform(s) for FORCE_PLATFORM:USED = {used}"
        )
    header = c3d["header"]
    point_rate = float(header["points"]["frame_rate"])
    analog_rate = float(header["analogs"]["frame_rate"])
    if not (point_rate > 0 and analog_rate > 0):
        raise LoperInputError(
            f"{source}: POINT:RATE = {point_rate:g} and ANALOG:RATE = {analog_rate:g} must be positive"
        )
    t0 = int(header["points"]["first_frame"]) / point_rate
    out = []
    for k, (pf, kind, chans) in enumerate(zip(platforms, types, plate_channels)):
        unit_pos = str(pf["unit_position"]).strip()
        unit_force = str(pf["unit_force"]).strip()
        if unit_pos.lower() not in LENGTH_UNITS_PER_M:
            raise LoperInputError(f"{source}: POINT:UNITS = '{unit_pos}' is not one of {', '.join(LENGTH_UNITS_PER_M)}")
        if unit_force != "N":
            raise LoperInputError(f"{source}: FORCE_PLATFORM:UNITS = '{unit_force}'; only N is supported")
        per_m = LENGTH_UNITS_PER_M[unit_pos.lower()]
        _moment_unit_check(params, k + 1, chans, kind, 1.0 / per_m, source)
        force = np.asarray(pf["force"], dtype=float).T.copy()
        moment = np.asarray(pf["moment"], dtype=float).T / per_m
        corners = np.asarray(pf["corners"], dtype=float).T / per_m
        if not (np.all(np.isfinite(force)) and np.all(np.isfinite(moment)) and np.all(np.isfinite(corners))):
            raise LoperInputError(f"{source}: platform {k + 1} holds non-finite forces, moments or corners")
        frame = _plate_frame(corners)
        _check_force_direction(
            force, frame[:, 2], lab_up, np.asarray(pf["corners"], dtype=float).T, unit_pos, (k + 1, chans), source
        )
        if frame[:, 2] @ lab_up > 0:  # corners the other way round: the surface lies at positive plate z
            origin = np.asarray(pf["origin"], dtype=float).ravel() / per_m  # ezc3d's, z <= 0, plate frame, m
            if kind == 3:
                origin = np.array([0.0, 0.0, origin[2]])
            moment = moment - 2.0 * np.cross(force, frame @ origin)
        out.append(
            ForcePlatform(
                number=k + 1,
                type=kind,
                channels=chans,
                analog_rate_hz=analog_rate,
                time_s=t0 + np.arange(force.shape[0]) / analog_rate,
                force_n=force,
                moment_nm=moment,
                corners_m=corners,
                centre_m=corners.mean(axis=0),
                source=source,
            )
        )
    return out
