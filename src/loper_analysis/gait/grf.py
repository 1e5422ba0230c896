"""Ground reaction of force platforms: resting level, centre of pressure, free moment, external-loads table.

Inputs are the arrays of one plate as read from a C3D file
(:class:`loper_analysis.io.force_platforms.ForcePlatform`): the force the
plate exerts on the body (N) and its moment about the centre of the plate's
top surface (N·m), both (n_samples, 3) in the lab frame, and the plate's
corners (4, 3) in m.

The lab's vertical
    ``up`` is the lab's up direction (unit vector, lab frame): lab +Z by
    default (:data:`loper_analysis.constants.LAB_Z_UP`, Qualisys and Vicon
    labs), or the direction the lab-to-model rotation turns into the
    model's +Y (:func:`loper_analysis.motion.markers.lab_up`; +Y for a Y-up lab
    such as BTS). The vertical force is ``F . up``. The order in which a file
    lists a plate's corners (either way round the plate) only sets the sign
    of the normal their diagonals give; the normal is turned to point along
    ``up`` (:func:`surface_normal`), so the corner order changes nothing below.

Resting level (:func:`resting_level`)
    Unloaded plates do not read zero (public files read -14 to -71 N). With
    ``v`` the vertical force ``F . up``, the floor is the 1st percentile of
    ``v`` and the unloaded samples are those with ``v <= floor + band_n``;
    the resting level is the median of each force and moment component over
    them. The rule needs the plate to be unloaded for at least about 1 % of
    the trial; a plate loaded throughout (a resting vertical force beyond
    ``max_rest_n`` in magnitude) is refused.

Centre of pressure and free moment (:func:`centre_of_pressure`)
    For a plate whose top surface has the unit normal ``n`` through the
    centre ``C``, with force ``F`` and moment ``M`` about ``C``:
    ``COP = C + (n x M) / (n . F)`` (a point on the surface) and the free
    moment ``T = n . (M - (COP - C) x F)`` about ``n`` (upward), so that
    ``M = (COP - C) x F + T n``. The COP does not depend on the sign of
    ``n``; ``T`` is taken about the normal turned up, and the torque ``T n``
    written to the ``.mot`` does not depend on it either.

Loaded and unloaded samples (:func:`plate_loads`)
    A sample is loaded when the vertical force above the resting level
    exceeds ``threshold_n``. While unloaded the force and the free moment
    are written as exactly 0 and the COP takes the value of the nearest
    loaded sample in time (the earlier one on a tie), so it never jumps at
    touch-down or lift-off (it jumps only halfway through an unloaded
    interval, where the force is zero on both sides); a plate that is never
    loaded keeps its COP at the surface centre.

Rotation to the model frame (:func:`external_loads_table`)
    Force, COP and torque are rotated with
    :func:`loper_analysis.motion.markers.rotate_markers` (``(-90, 0, 0)`` takes a
    Z-up lab into OpenSim's Y-up frame).

From a recording's force platforms (:func:`plates_loads`, :func:`plate_vertical_loads`)
    Every plate of a file read (:func:`loper_analysis.io.force_platforms.read_force_platforms`)
    and analysed as above; shared by the ``grf`` and ``events`` steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from loper_analysis.checks import number, where
from loper_analysis.constants import (
    LAB_TO_MODEL_ROTATION_DEG,
    LAB_Z_UP,
    LOADED_THRESHOLD_N,
    MAX_RESTING_N,
    RESTING_BAND_N,
)
from loper_analysis.errors import LoperInputError
from loper_analysis.motion.markers import rotate_markers

__all__ = [
    "EXTERNAL_LOADS_SUFFIXES",
    "MAX_TILT_DEG",
    "ROTATION_SETTING",
    "PlateLoads",
    "VerticalLoads",
    "centre_of_pressure",
    "external_loads_columns",
    "external_loads_table",
    "plate_loads",
    "plate_vertical_loads",
    "plates_loads",
    "resting_level",
    "surface_normal",
    "up_vector",
    "vertical_loads",
]


#: Column suffixes of one plate in the external-loads table (force N, point m, torque N·m).
EXTERNAL_LOADS_SUFFIXES: tuple[str, ...] = (
    "ground_force_vx",
    "ground_force_vy",
    "ground_force_vz",
    "ground_force_px",
    "ground_force_py",
    "ground_force_pz",
    "ground_torque_x",
    "ground_torque_y",
    "ground_torque_z",
)

#: Percentile of the vertical force taken as the unloaded floor.
_FLOOR_PERCENTILE = 1.0
#: Largest angle between a plate's surface normal and the lab's up direction, deg.
MAX_TILT_DEG = 45.0
#: Setting that fixes the lab's up direction (named in messages).
ROTATION_SETTING = "markers.lab_to_model_rotation_deg"


@dataclass(frozen=True)
class PlateLoads:
    """Ground reaction of one plate after removing its resting level, lab frame.

    Attributes
    ----------
    number : int
        Plate number (1-based).
    time_s : numpy.ndarray
        Shape (n,), s.
    force_n : numpy.ndarray
        Shape (n, 3), N: force on the body minus the resting level, every sample (not zeroed while unloaded).
    moment_nm : numpy.ndarray
        Shape (n, 3), N·m about ``centre_m``, minus the resting level.
    cop_m : numpy.ndarray
        Shape (n, 3), m: centre of pressure on the top surface (the unloaded policy applied).
    free_moment_nm : numpy.ndarray
        Shape (n,), N·m about the upward surface normal; 0 while unloaded.
    loaded : numpy.ndarray
        Shape (n,), bool: vertical force above the resting level > threshold.
    rest_force_n, rest_moment_nm : numpy.ndarray
        Shape (3,): the resting level removed (N, N·m).
    normal : numpy.ndarray
        Shape (3,): unit normal of the top surface, turned along ``up``.
    corners_m : numpy.ndarray
        Shape (4, 3), m.
    centre_m : numpy.ndarray
        Shape (3,), m.
    up : numpy.ndarray
        Shape (3,): the lab's up direction (unit vector) that defines the vertical.
    """

    number: int
    time_s: np.ndarray
    force_n: np.ndarray
    moment_nm: np.ndarray
    cop_m: np.ndarray
    free_moment_nm: np.ndarray
    loaded: np.ndarray
    rest_force_n: np.ndarray
    rest_moment_nm: np.ndarray
    normal: np.ndarray
    corners_m: np.ndarray
    centre_m: np.ndarray
    up: np.ndarray = field(default_factory=lambda: np.array(LAB_Z_UP))


@dataclass(frozen=True)
class VerticalLoads:
    """Vertical force of each plate above its resting level, for event detection.

    Attributes
    ----------
    time_s : numpy.ndarray
        Shape (n,), s, analog rate.
    vertical_n : numpy.ndarray
        Shape (n, n_plates), N: vertical force (along each plate's ``up``) on the body above the resting level
        (positive while loaded).
    rest_vertical_n : numpy.ndarray
        Shape (n_plates,), N: the resting vertical level that was removed.
    corners_m : numpy.ndarray
        Shape (n_plates, 4, 3), m, model frame (rotated like the markers).
    numbers : tuple of int
        Plate numbers, 1-based, one per column.
    """

    time_s: np.ndarray
    vertical_n: np.ndarray
    rest_vertical_n: np.ndarray
    corners_m: np.ndarray
    numbers: tuple[int, ...]


def external_loads_columns(number: int) -> list[str]:
    """The nine .mot column names of plate ``number``: ``{n}_ground_force_vx`` ... ``{n}_ground_torque_z``."""
    return [f"{int(number)}_{s}" for s in EXTERNAL_LOADS_SUFFIXES]


def _vectors(name: str, values, source: str, n: int | None = None) -> np.ndarray:
    X = np.asarray(values, dtype=float)
    if X.ndim != 2 or X.shape[1] != 3 or (n is not None and X.shape[0] != n) or X.shape[0] == 0:
        want = f"({n}, 3)" if n is not None else "(n >= 1, 3)"
        raise LoperInputError(f"{where(source)}{name} must have shape {want}, got {X.shape}")
    if not np.all(np.isfinite(X)):
        raise LoperInputError(f"{where(source)}{name} is not finite at row {int(np.argwhere(~np.isfinite(X))[0, 0])}")
    return X


def up_vector(up: Sequence[float], source: str = "") -> np.ndarray:
    """The lab's up direction as a unit vector: ``up`` checked and normalised.

    Parameters
    ----------
    up : array_like
        Shape (3,): a direction in the lab frame (any length > 0), e.g.
        :data:`loper_analysis.constants.LAB_Z_UP` or
        :func:`loper_analysis.motion.markers.lab_up` of the lab-to-model rotation.
    source : str
        The file (and plate), quoted in messages.

    Returns
    -------
    numpy.ndarray
        Shape (3,), unit vector, lab frame (a new array).

    Raises
    ------
    LoperInputError
        ``up`` is not 3 finite numbers or is the zero vector.
    """
    try:
        u = np.array(up, dtype=float)
    except (TypeError, ValueError):
        raise LoperInputError(f"{where(source)}up must be 3 numbers (a direction, lab frame), got {up!r}") from None
    norm = float(np.linalg.norm(u)) if u.shape == (3,) and np.all(np.isfinite(u)) else 0.0
    if norm == 0.0:
        raise LoperInputError(
            f"{where(source)}up must be 3 finite numbers, not all 0 (a direction, lab frame), got {up!r}"
        )
    return u / norm


def surface_normal(corners_m, source: str = "", up: Sequence[float] = LAB_Z_UP) -> np.ndarray:
    """Unit normal of a plate's top surface from its four corners, turned to point along the lab's up direction.

    The normal is the cross product of the diagonals; listing the corners
    the other way round the plate only flips it, and it is then turned so
    that ``normal . up > 0``. A plate must lie within :data:`MAX_TILT_DEG`
    (45 deg) of level: its normal at most that far from ``up``.

    Parameters
    ----------
    corners_m : array_like
        Shape (4, 3), m, lab frame, in order around the plate (either way round).
    source : str
        The file and plate, quoted in messages.
    up : array_like
        Shape (3,): the lab's up direction, lab frame (normalised here); default
        lab +Z (:data:`loper_analysis.constants.LAB_Z_UP`). For a lab of another
        orientation :func:`loper_analysis.motion.markers.lab_up` of the lab-to-model rotation.

    Returns
    -------
    numpy.ndarray
        Shape (3,): unit normal, ``normal . up >= cos(45 deg)``.

    Raises
    ------
    LoperInputError
        Bad shape, degenerate corners, a bad ``up``, or a plate not facing up
        (normal more than 45 degrees from ``up``; the message names the normal,
        ``up`` and the setting :data:`ROTATION_SETTING` that fixes ``up``).
    """
    u = up_vector(up, source)
    C = np.asarray(corners_m, dtype=float)
    if C.shape != (4, 3) or not np.all(np.isfinite(C)):
        raise LoperInputError(f"{where(source)}corners_m must be 4 finite corners (4, 3), got shape {C.shape}")
    n = np.cross(C[0] - C[2], C[1] - C[3])  # diagonals: robust to the corner numbering's direction
    norm = float(np.linalg.norm(n))
    if norm == 0.0:
        raise LoperInputError(f"{where(source)}the plate corners {C.tolist()} do not span a surface")
    n = n / norm
    if n @ u < 0:
        n = -n
    if n @ u < np.cos(np.radians(MAX_TILT_DEG)):
        angle = float(np.degrees(np.arccos(np.clip(n @ u, -1.0, 1.0))))
        raise LoperInputError(
            f"{where(source)}the plate does not face up: surface normal {np.round(n, 3).tolist()} is {angle:.1f} deg "
            f"from the up direction {np.round(u, 3).tolist()} (at most {MAX_TILT_DEG:g} deg); the lab's up is the "
            f"direction {ROTATION_SETTING} turns into the model's +Y: check that setting for this lab"
        )
    return n


def resting_level(
    force_n,
    moment_nm,
    band_n: float = RESTING_BAND_N,
    max_rest_n: float = MAX_RESTING_N,
    source: str = "",
    up: Sequence[float] = LAB_Z_UP,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Resting (unloaded) level of a plate's force and moment.

    Parameters
    ----------
    force_n, moment_nm : array_like
        Shape (n, 3): force on the body (N, lab frame) and its moment (N·m).
    band_n : float
        Width above the floor (1st percentile of the vertical force
        ``force_n . up``) within which a sample counts as unloaded, N (> 0).
    max_rest_n : float
        Largest plausible resting vertical force magnitude, N (> 0).
    source : str
        The file and plate, quoted in messages.
    up : array_like
        Shape (3,): the lab's up direction (see :func:`surface_normal`); default lab +Z.

    Returns
    -------
    rest_force_n, rest_moment_nm : numpy.ndarray
        Shape (3,): medians over the unloaded samples.
    unloaded : numpy.ndarray
        Shape (n,), bool: the samples used.

    Raises
    ------
    LoperInputError
        Bad shapes or parameters; a resting vertical force beyond
        ``max_rest_n`` (the plate is never unloaded, or holds the force on
        the plate rather than on the body).
    """
    F = _vectors("force_n", force_n, source)
    M = _vectors("moment_nm", moment_nm, source, F.shape[0])
    band = number("band_n", band_n, source, minimum=0.0)
    limit = number("max_rest_n", max_rest_n, source, minimum=0.0)
    u = up_vector(up, source)
    v = F @ u
    floor = float(np.percentile(v, _FLOOR_PERCENTILE))
    unloaded = v <= floor + band
    rest_f = np.median(F[unloaded], axis=0)
    rest_m = np.median(M[unloaded], axis=0)
    rest_v = float(rest_f @ u)
    if abs(rest_v) > limit:
        raise LoperInputError(
            f"{where(source)}resting vertical force {rest_v:.1f} N exceeds {limit:g} N in magnitude: the plate is "
            "never unloaded, or its force points down while loaded (force on the plate instead of on the body)"
        )
    return rest_f, rest_m, unloaded


def centre_of_pressure(force_n, moment_nm, centre_m, normal) -> tuple[np.ndarray, np.ndarray]:
    """Centre of pressure on the plate surface and free moment about its normal.

    Parameters
    ----------
    force_n, moment_nm : array_like
        Shape (n, 3): force (N) and its moment about ``centre_m`` (N·m).
    centre_m : array_like
        Shape (3,), m: a point of the top surface.
    normal : array_like
        Shape (3,): unit normal of the surface.

    Returns
    -------
    cop_m : numpy.ndarray
        Shape (n, 3), m; NaN where the normal force is exactly 0.
    free_moment_nm : numpy.ndarray
        Shape (n,), N·m about ``normal``; NaN where the COP is.
    """
    F = np.asarray(force_n, dtype=float)
    M = np.asarray(moment_nm, dtype=float)
    c = np.asarray(centre_m, dtype=float)
    n = np.asarray(normal, dtype=float)
    fn = F @ n
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.cross(n, M) / fn[:, None]
    r[fn == 0] = np.nan
    free = (M - np.cross(r, F)) @ n
    return c + r, free


def _nearest_loaded(loaded: np.ndarray) -> np.ndarray | None:
    """For every sample the index of the nearest loaded sample (earlier on ties); None when none is loaded."""
    idx = np.flatnonzero(loaded)
    if idx.size == 0:
        return None
    k = np.arange(loaded.size)
    after = np.searchsorted(idx, k)  # first loaded index >= k
    nxt = idx[np.minimum(after, idx.size - 1)]
    prv = idx[np.maximum(after - 1, 0)]
    use_prev = (after > 0) & ((after == idx.size) | (k - prv <= nxt - k))
    return np.where(use_prev, prv, nxt)


def plate_loads(
    plate_number: int,
    time_s,
    force_n,
    moment_nm,
    corners_m,
    *,
    threshold_n: float = LOADED_THRESHOLD_N,
    band_n: float = RESTING_BAND_N,
    max_rest_n: float = MAX_RESTING_N,
    source: str = "",
    up: Sequence[float] = LAB_Z_UP,
) -> PlateLoads:
    """Resting level removed, COP and free moment of one plate, with the unloaded policy of the module notes.

    Parameters
    ----------
    plate_number : int
        Plate number (1-based).
    time_s : array_like
        Shape (n,), s.
    force_n, moment_nm : array_like
        Shape (n, 3), lab frame: force on the body (N) and its moment about
        the surface centre (mean of the corners), N·m.
    corners_m : array_like
        Shape (4, 3), m, lab frame.
    threshold_n : float
        Vertical force above the resting level from which a sample is loaded, N (> 0).
    band_n, max_rest_n : float
        See :func:`resting_level`.
    source : str
        The file and plate, quoted in messages.
    up : array_like
        Shape (3,): the lab's up direction, lab frame (see :func:`surface_normal`);
        default lab +Z. The vertical force is ``force_n . up``.

    Raises
    ------
    LoperInputError
        Bad shapes or parameters, a plate not facing up, an implausible resting level.
    """
    t = np.asarray(time_s, dtype=float)
    F = _vectors("force_n", force_n, source)
    M = _vectors("moment_nm", moment_nm, source, F.shape[0])
    if t.shape != (F.shape[0],) or not np.all(np.isfinite(t)):
        raise LoperInputError(f"{where(source)}time_s must be {F.shape[0]} finite times, got shape {t.shape}")
    threshold = number("threshold_n", threshold_n, source, minimum=0.0)
    u = up_vector(up, source)
    normal = surface_normal(corners_m, source, u)
    corners = np.asarray(corners_m, dtype=float)
    centre = corners.mean(axis=0)
    rest_f, rest_m, _ = resting_level(F, M, band_n, max_rest_n, source, u)
    F = F - rest_f
    M = M - rest_m
    loaded = F @ u > threshold
    cop, free = centre_of_pressure(F, M, centre, normal)
    nearest = _nearest_loaded(loaded)
    if nearest is None:
        cop = np.tile(centre, (F.shape[0], 1))
    else:
        cop = cop[nearest]
    free = np.where(loaded, free, 0.0)
    return PlateLoads(
        number=int(plate_number),
        time_s=t.copy(),
        force_n=F,
        moment_nm=M,
        cop_m=cop,
        free_moment_nm=free,
        loaded=loaded,
        rest_force_n=rest_f,
        rest_moment_nm=rest_m,
        normal=normal,
        corners_m=corners.copy(),
        centre_m=centre,
        up=u,
    )


def external_loads_table(loads: Sequence[PlateLoads], rotation_deg: Sequence[float] = (0.0, 0.0, 0.0)) -> pd.DataFrame:
    """The external-loads table of OpenSim: one row per sample, nine columns per plate, model frame.

    Parameters
    ----------
    loads : sequence of PlateLoads
        Plates on one time base (same ``time_s``), unique numbers.
    rotation_deg : sequence of float
        Lab -> model rotation, as :func:`loper_analysis.motion.markers.rotate_markers`.

    Returns
    -------
    pandas.DataFrame
        ``time_s`` (s), then for each plate n the columns of
        :func:`external_loads_columns`: force on the body (N; 0 while
        unloaded), COP (m), free-moment torque (N·m; the free moment times the
        surface normal, 0 while unloaded).

    Raises
    ------
    LoperInputError
        No plates, duplicate numbers, different time bases, a bad rotation.
    """
    loads = list(loads)
    if not loads:
        raise LoperInputError("external loads need at least one force platform")
    numbers = [p.number for p in loads]
    if len(set(numbers)) != len(numbers):
        raise LoperInputError(f"plate numbers must be unique, got {numbers}")
    t = loads[0].time_s
    for p in loads[1:]:
        if p.time_s.shape != t.shape or not np.array_equal(p.time_s, t):
            raise LoperInputError(f"plate {p.number} is not on the time base of plate {loads[0].number}")
    out: dict[str, np.ndarray] = {"time_s": t.copy()}
    for p in loads:
        force = np.where(p.loaded[:, None], p.force_n, 0.0)
        torque = p.free_moment_nm[:, None] * p.normal
        block = np.hstack(
            [
                rotate_markers(force, rotation_deg),
                rotate_markers(p.cop_m, rotation_deg),
                rotate_markers(torque, rotation_deg),
            ]
        )
        for j, name in enumerate(external_loads_columns(p.number)):
            out[name] = block[:, j]
    return pd.DataFrame(out)


def vertical_loads(loads: Sequence[PlateLoads], rotation_deg: Sequence[float] = (0.0, 0.0, 0.0)) -> VerticalLoads:
    """Each plate's lab-vertical force above its resting level, with the corners in the model frame.

    The vertical force is the component of :attr:`PlateLoads.force_n` along
    the plate's :attr:`PlateLoads.up` (the lab's up direction) at the analog
    rate, positive while loaded, not zeroed while unloaded (a threshold with
    hysteresis belongs to the event detection).

    Raises
    ------
    LoperInputError
        No plates, or plates on different time bases.
    """
    loads = list(loads)
    if not loads:
        raise LoperInputError("vertical loads need at least one force platform")
    t = loads[0].time_s
    for p in loads[1:]:
        if not np.array_equal(p.time_s, t):
            raise LoperInputError(f"plate {p.number} is not on the time base of plate {loads[0].number}")
    return VerticalLoads(
        time_s=t.copy(),
        vertical_n=np.column_stack([p.force_n @ p.up for p in loads]),
        rest_vertical_n=np.array([p.rest_force_n @ p.up for p in loads]),
        corners_m=np.stack([rotate_markers(p.corners_m, rotation_deg) for p in loads]),
        numbers=tuple(p.number for p in loads),
    )


def plates_loads(
    plates: Sequence,
    threshold_n: float,
    band_n: float,
    max_rest_n: float,
    up: Sequence[float] | None = None,
    source: str = "",
) -> list[PlateLoads]:
    """Every plate of a recording analysed (:func:`plate_loads`), lab frame.

    ``plates``: the recording's force platforms (:func:`loper_analysis.io.force_platforms.read_force_platforms`,
    read with the same ``up``). ``up``: the lab's up direction, lab frame (None: lab +Z); a plate more than
    :data:`MAX_TILT_DEG` from level is refused, naming ``source`` (the file), the plate, its normal and ``up``.
    """
    lab_up = up_vector(LAB_Z_UP if up is None else up, source)
    return [
        plate_loads(
            p.number,
            p.time_s,
            p.force_n,
            p.moment_nm,
            p.corners_m,
            threshold_n=threshold_n,
            band_n=band_n,
            max_rest_n=max_rest_n,
            source=f"{source} (force platform {p.number})",
            up=lab_up,
        )
        for p in plates
    ]


def plate_vertical_loads(
    plates: Sequence,
    rotation_deg: Sequence[float] = LAB_TO_MODEL_ROTATION_DEG,
    band_n: float = RESTING_BAND_N,
    max_rest_n: float = MAX_RESTING_N,
    up: Sequence[float] | None = None,
    source: str = "",
) -> VerticalLoads:
    """Each plate of a recording: its lab-vertical force above its resting level at the analog rate, corners in
    the model frame (:func:`vertical_loads` of :func:`plates_loads`).

    ``plates`` and ``up`` (the lab's up direction, lab frame; None: lab +Z) as in :func:`plates_loads`.
    """
    return vertical_loads(plates_loads(plates, 20.0, band_n, max_rest_n, up, source), rotation_deg)
