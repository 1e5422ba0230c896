"""Marker processing: gap filling and the lab-to-model rotation.

Markers are arrays (n_frames, n_markers, 3) in metres, NaN where missing
(as returned by :func:`loper_analysis.io.c3d.read_c3d`). A marker counts as
missing in a frame if any of its three coordinates is NaN. Frame numbers in
messages and reports are 0-based indices into the array.
"""

from __future__ import annotations

from collections.abc import Sequence
from numbers import Integral

import numpy as np
import pandas as pd
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

from .errors import LoperInputError

__all__ = [
    "GAP_REPORT_COLUMNS",
    "fill_gaps",
    "rotate_markers",
]

#: Columns of the gap report of :func:`fill_gaps`.
GAP_REPORT_COLUMNS: tuple[str, ...] = ("marker", "first_frame", "last_frame", "n_frames")

#: Problems listed in one error message before the rest are only counted.
_MAX_LISTED = 10


def _check_markers(markers_m, source: str) -> np.ndarray:
    X = np.array(markers_m, dtype=float)  # a copy: the input is never modified
    if X.ndim != 3 or X.shape[2] != 3:
        raise LoperInputError(f"{source}: markers_m must have shape (n_frames, n_markers, 3), got {X.shape}")
    if np.any(np.isinf(X)):
        f, m, _ = np.argwhere(np.isinf(X))[0]
        raise LoperInputError(f"{source}: markers_m is infinite at frame {f}, marker index {m}")
    return X


def _missing_runs(missing: np.ndarray) -> list[tuple[int, int]]:
    """Runs of True in a 1-D bool array as (first, last) index pairs, inclusive."""
    edges = np.diff(np.r_[0, missing.astype(np.int8), 0])
    starts = np.flatnonzero(edges == 1)
    stops = np.flatnonzero(edges == -1) - 1
    return list(zip(starts.tolist(), stops.tolist()))


def _gap_problems(label: str, runs: list[tuple[int, int]], n_frames: int, max_gap: int) -> list[str]:
    """Messages for the runs that cannot be filled: touching an edge, or longer than ``max_gap``."""
    problems = []
    for first, last in runs:
        n = last - first + 1
        if first == 0 or last == n_frames - 1:
            edge = "start" if first == 0 else "end"
            problems.append(
                f"marker {label} is missing in frames {first}..{last} ({n} frame{'s' * (n != 1)}) at the {edge} "
                "of the trial, which cannot be interpolated; trim the trial"
            )
        elif n > max_gap:
            problems.append(
                f"marker {label} is missing in frames {first}..{last}: a gap of {n} frames exceeds the limit "
                f"of {max_gap} frames"
            )
    return problems


def fill_gaps(
    markers_m, max_gap_frames: int, labels: Sequence[str], source: str = ""
) -> tuple[np.ndarray, pd.DataFrame]:
    """Fill short interior gaps of each marker with a cubic spline through its valid frames.

    For each marker with gaps, one ``scipy.interpolate.CubicSpline``
    (not-a-knot ends) of the frame index is fitted through all frames where
    the marker is present (x, y and z together) and evaluated in the missing
    frames; a trajectory that is a cubic polynomial of time is therefore
    reproduced exactly.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres, NaN where missing; a frame
        with any NaN coordinate counts as missing. Not modified.
    max_gap_frames : int
        Longest run of missing frames that may be filled (>= 0).
    labels : sequence of str
        One name per marker (for messages and the report).
    source : str
        File the markers came from (for messages).

    Returns
    -------
    filled : numpy.ndarray
        Shape (n_frames, n_markers, 3), metres, without NaN.
    report : pandas.DataFrame
        One row per filled gap, columns :data:`GAP_REPORT_COLUMNS`:
        ``marker`` (str), ``first_frame``, ``last_frame`` (0-based,
        inclusive) and ``n_frames`` (int); empty if nothing was filled.

    Raises
    ------
    LoperInputError
        Bad shapes or ``max_gap_frames``, infinite values, a marker missing
        in every frame, a gap touching the start or end of the trial, or an
        interior gap longer than ``max_gap_frames``. The message names the
        source file and lists every such marker with its first and last
        missing frame and the gap length.
    """
    where = source or "markers"
    X = _check_markers(markers_m, where)
    labels = [str(lab) for lab in labels]
    if len(labels) != X.shape[1]:
        raise LoperInputError(f"{where}: labels must name {X.shape[1]} markers, got {len(labels)}")
    if isinstance(max_gap_frames, bool) or not isinstance(max_gap_frames, Integral) or max_gap_frames < 0:
        raise LoperInputError(f"{where}: max_gap_frames must be an integer >= 0, got {max_gap_frames!r}")
    n_frames = X.shape[0]
    missing = ~np.all(np.isfinite(X), axis=2)  # (n_frames, n_markers)
    problems: list[str] = []
    rows = []
    for j, label in enumerate(labels):
        if not missing[:, j].any():
            continue
        if missing[:, j].all():
            problems.append(f"marker {label} is missing in every frame (0..{n_frames - 1})")
            continue
        runs = _missing_runs(missing[:, j])
        bad = _gap_problems(label, runs, n_frames, int(max_gap_frames))
        if bad:
            problems.extend(bad)
            continue
        valid = np.flatnonzero(~missing[:, j])
        gaps = np.flatnonzero(missing[:, j])
        X[gaps, j] = CubicSpline(valid, X[valid, j])(gaps)
        rows += [(label, first, last, last - first + 1) for first, last in runs]
    if problems:
        more = len(problems) - _MAX_LISTED
        listed = "; ".join(problems[:_MAX_LISTED]) + (f"; and {more} more" if more > 0 else "")
        raise LoperInputError(f"{where}: cannot fill marker gaps: {listed}")
    report = pd.DataFrame(rows, columns=list(GAP_REPORT_COLUMNS)).astype(
        {"marker": object, "first_frame": np.int64, "last_frame": np.int64, "n_frames": np.int64}
    )
    return X, report


def rotate_markers(markers_m, rotation_deg: Sequence[float]) -> np.ndarray:
    """Rotate lab-frame points into the model frame.

    The rotation is ``R = Rz(c) @ Ry(b) @ Rx(a)`` for ``rotation_deg = (a,
    b, c)``: first a turn by ``a`` degrees about the fixed X axis, then by
    ``b`` about the fixed Y axis, then by ``c`` about the fixed Z axis
    (extrinsic "xyz", ``Rotation.from_euler("xyz", ..., degrees=True)``),
    each counter-clockwise (right-hand rule) when looking down the axis; a
    point ``p`` becomes ``R @ p``. Example: ``(-90, 0, 0)`` takes Qualisys's
    Z-up lab into OpenSim's Y-up frame, ``(x, y, z) -> (x, z, -y)``.

    Parameters
    ----------
    markers_m : array_like
        Shape (..., 3), metres (e.g. (n_frames, n_markers, 3)); NaN stays NaN
        (a NaN coordinate makes the whole rotated point NaN).
    rotation_deg : sequence of float
        Three finite angles (degrees) about X, Y, Z, applied in that order.

    Returns
    -------
    numpy.ndarray
        Same shape as ``markers_m``, metres, model frame; a new array.

    Raises
    ------
    LoperInputError
        If the last axis is not 3 or ``rotation_deg`` is not 3 finite numbers.
    """
    X = np.asarray(markers_m, dtype=float)
    if X.ndim < 1 or X.shape[-1] != 3:
        raise LoperInputError(f"markers_m must have shape (..., 3), got {X.shape}")
    try:
        angles = np.asarray(rotation_deg, dtype=float)
    except (TypeError, ValueError):
        raise LoperInputError(f"rotation_deg must be 3 angles in degrees, got {rotation_deg!r}") from None
    if angles.shape != (3,) or not np.all(np.isfinite(angles)):
        raise LoperInputError(f"rotation_deg must be 3 finite angles in degrees (about X, Y, Z), got {rotation_deg!r}")
    R = Rotation.from_euler("xyz", angles, degrees=True).as_matrix()
    return X @ R.T
