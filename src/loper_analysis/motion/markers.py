"""Marker processing: gap filling, gap summaries, the markers-per-frame rule of IK and the lab-to-model rotation.

Markers are arrays (n_frames, n_markers, 3) in metres, NaN where missing
(as returned by :func:`loper_analysis.io.c3d.read_c3d`). A marker counts as
missing in a frame if any of its three coordinates is NaN. Frame numbers in
messages and reports are 0-based indices into the array.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from numbers import Integral

import numpy as np
import pandas as pd

from loper_analysis.errors import LoperInputError

__all__ = [
    "GAP_REPORT_COLUMNS",
    "GAP_SUMMARY_COLUMNS",
    "MODEL_UP",
    "fill_gaps",
    "frames_with_markers",
    "gap_summary",
    "lab_up",
    "require_markers_per_frame",
    "rotate_markers",
]

#: Columns of the gap report of :func:`fill_gaps`.
GAP_REPORT_COLUMNS: tuple[str, ...] = ("marker", "first_frame", "last_frame", "n_frames")

#: Columns of the per-marker summary of :func:`gap_summary`.
GAP_SUMMARY_COLUMNS: tuple[str, ...] = (
    "marker",
    "n_frames",
    "n_filled_frames",
    "n_missing_frames",
    "longest_gap_frames",
    "n_unfiltered_frames",
)

#: Problems listed in one error message before the rest are only counted.
_MAX_LISTED = 10

#: Up direction of the model frame (OpenSim's +Y), model frame.
MODEL_UP: tuple[float, float, float] = (0.0, 1.0, 0.0)
#: Interior gaps up to this many frames are filled (config ``markers.max_gap_frames``).
MAX_GAP_FRAMES: int = 10
#: Components of :func:`lab_up` smaller than this in magnitude are set to 0 (quarter turns give exact axes).
_AXIS_ROUND_OFF = 1e-12


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
    markers_m, max_gap_frames: int, labels: Sequence[str], source: str = "", unfillable: str = "error"
) -> tuple[np.ndarray, pd.DataFrame]:
    """Fill short interior gaps of each marker with a cubic spline through its valid frames.

    For each marker with gaps to fill, one ``scipy.interpolate.CubicSpline``
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
        Longest run of missing frames that may be filled (>= 0; 0 fills nothing).
    labels : sequence of str
        One name per marker (for messages and the report).
    source : str
        File the markers came from (for messages).
    unfillable : {"error", "keep"}
        What to do with a gap that cannot be filled (touching the start or
        end of the trial, longer than ``max_gap_frames``, or a marker missing
        in every frame): ``"error"`` refuses the trial, ``"keep"`` leaves
        those frames NaN (real recordings; :func:`gap_summary` counts them).

    Returns
    -------
    filled : numpy.ndarray
        Shape (n_frames, n_markers, 3), metres; without NaN when
        ``unfillable="error"``, NaN in the unfilled gaps otherwise.
    report : pandas.DataFrame
        One row per filled gap, columns :data:`GAP_REPORT_COLUMNS`:
        ``marker`` (str), ``first_frame``, ``last_frame`` (0-based,
        inclusive) and ``n_frames`` (int); empty if nothing was filled.

    Raises
    ------
    LoperInputError
        Bad shapes, ``max_gap_frames`` or ``unfillable``, infinite values;
        with ``unfillable="error"`` also a marker missing in every frame, a
        gap touching the start or end of the trial, or an interior gap
        longer than ``max_gap_frames``. The message names the source file
        and lists every such marker with its first and last missing frame
        and the gap length.
    """
    from scipy.interpolate import CubicSpline  # here, not at the top: IK imports this module

    where = source or "markers"
    X = _check_markers(markers_m, where)
    labels = [str(lab) for lab in labels]
    if len(labels) != X.shape[1]:
        raise LoperInputError(f"{where}: labels must name {X.shape[1]} markers, got {len(labels)}")
    if isinstance(max_gap_frames, bool) or not isinstance(max_gap_frames, Integral) or max_gap_frames < 0:
        raise LoperInputError(f"{where}: max_gap_frames must be an integer >= 0, got {max_gap_frames!r}")
    if unfillable not in ("error", "keep"):
        raise LoperInputError(f"{where}: unfillable must be 'error' or 'keep', got {unfillable!r}")
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
        if bad and unfillable == "error":
            problems.extend(bad)
            continue
        runs = [(a, b) for a, b in runs if a > 0 and b < n_frames - 1 and b - a + 1 <= max_gap_frames]
        if not runs:
            continue
        valid = np.flatnonzero(~missing[:, j])
        gaps = np.concatenate([np.arange(a, b + 1) for a, b in runs])
        X[gaps, j] = CubicSpline(valid, X[valid, j])(gaps)
        rows += [(label, first, last, last - first + 1) for first, last in runs]
    if problems and unfillable == "error":
        more = len(problems) - _MAX_LISTED
        listed = "; ".join(problems[:_MAX_LISTED]) + (f"; and {more} more" if more > 0 else "")
        raise LoperInputError(f"{where}: cannot fill marker gaps: {listed}")
    report = pd.DataFrame(rows, columns=list(GAP_REPORT_COLUMNS)).astype(
        {"marker": object, "first_frame": np.int64, "last_frame": np.int64, "n_frames": np.int64}
    )
    return X, report


def gap_summary(raw_m, processed_m, labels: Sequence[str], unfiltered=None) -> pd.DataFrame:
    """Per marker: frames filled, frames still missing and the longest remaining gap.

    Parameters
    ----------
    raw_m, processed_m : array_like
        Shape (n_frames, n_markers, 3), metres: the markers as read (NaN
        where missing) and after gap filling (and filtering); a frame with
        any NaN coordinate counts as missing.
    labels : sequence of str
        One name per marker.
    unfiltered : array_like of bool, optional
        Shape (n_frames, n_markers) or (n_frames, n_markers, 3): samples left
        unfiltered by :func:`loper_analysis.filtering.lowpass_finite_runs`.

    Returns
    -------
    pandas.DataFrame
        One row per marker, in order, columns :data:`GAP_SUMMARY_COLUMNS`:
        ``marker``, ``n_frames``, ``n_filled_frames`` (missing in ``raw_m``,
        present in ``processed_m``), ``n_missing_frames`` (missing in
        ``processed_m``), ``longest_gap_frames`` (longest run still missing;
        0 if none) and ``n_unfiltered_frames`` (int).
    """
    raw = ~np.all(np.isfinite(np.asarray(raw_m, float)), axis=2)
    out = ~np.all(np.isfinite(np.asarray(processed_m, float)), axis=2)
    labels = [str(lab) for lab in labels]
    if raw.shape != out.shape or raw.shape[1] != len(labels):
        raise LoperInputError(
            f"raw_m {raw.shape}, processed_m {out.shape} and {len(labels)} labels must describe the same markers"
        )
    if unfiltered is None:
        raw_kept = np.zeros_like(out)
    else:
        raw_kept = np.asarray(unfiltered, bool)
        raw_kept = raw_kept.any(axis=2) if raw_kept.ndim == 3 else raw_kept
    rows = []
    for j, label in enumerate(labels):
        runs = _missing_runs(out[:, j])
        rows.append(
            (
                label,
                out.shape[0],
                int((raw[:, j] & ~out[:, j]).sum()),
                int(out[:, j].sum()),
                max((b - a + 1 for a, b in runs), default=0),
                int(raw_kept[:, j].sum()),
            )
        )
    return pd.DataFrame(rows, columns=list(GAP_SUMMARY_COLUMNS)).astype(
        {c: (object if c == "marker" else np.int64) for c in GAP_SUMMARY_COLUMNS}
    )


def require_markers_per_frame(
    markers_m,
    labels: Sequence[str],
    min_markers: int = 3,
    weights: Mapping[str, float] | None = None,
    time_s=None,
    source: str = "",
) -> None:
    """Refuse a trial with a frame in which fewer than ``min_markers`` weighted markers are present.

    The rule: IK needs, in every frame, at least ``min_markers`` markers of
    positive weight (every marker of ``labels`` when ``weights`` is None)
    with finite coordinates. Three is the least that fixes one rigid body
    (if not collinear); it does not guarantee that every coordinate of a
    multi-segment model is determined, it only stops a solve that cannot
    give an answer at all.

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres, NaN where missing.
    labels : sequence of str
        One name per marker.
    min_markers : int
        Least number of weighted markers a frame must hold (>= 1).
    weights : mapping of str to float, optional
        IK weight per marker; markers absent from it or of weight <= 0 do not count.
    time_s : array_like, optional
        Shape (n_frames,), s; frame times for the message.
    source : str
        File the markers came from (for the message).

    Raises
    ------
    LoperInputError
        Naming the file, the rule, the frames (0-based runs, with their
        times when given) and the weighted markers missing in them.
    """
    where = source or "markers"
    X = np.asarray(markers_m, dtype=float)
    labels = [str(lab) for lab in labels]
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[1] != len(labels):
        raise LoperInputError(f"{where}: markers_m must have shape (n_frames, {len(labels)}, 3), got {X.shape}")
    if isinstance(min_markers, bool) or not isinstance(min_markers, Integral) or min_markers < 1:
        raise LoperInputError(f"{where}: min_markers must be an integer >= 1, got {min_markers!r}")
    used = [j for j, lab in enumerate(labels) if weights is None or float(weights.get(lab, 0.0)) > 0]
    present = np.all(np.isfinite(X[:, used]), axis=2)  # (n_frames, n_used)
    short = present.sum(axis=1) < min_markers
    if not short.any():
        return
    runs = _missing_runs(short)
    t = None if time_s is None else np.asarray(time_s, float)
    spans = []
    for a, b in runs[:_MAX_LISTED]:
        span = f"{a}..{b}" if b > a else f"{a}"
        if t is not None:
            span += f" (t = {t[a]:.4f}..{t[b]:.4f} s)" if b > a else f" (t = {t[a]:.4f} s)"
        spans.append(span)
    if len(runs) > _MAX_LISTED:
        spans.append(f"and {len(runs) - _MAX_LISTED} more run(s)")
    absent = [labels[used[k]] for k in np.flatnonzero((~present[short]).any(axis=0))]
    if len(absent) > 2 * _MAX_LISTED:
        absent = absent[: 2 * _MAX_LISTED] + [f"and {len(absent) - 2 * _MAX_LISTED} more"]
    raise LoperInputError(
        f"{where}: {int(short.sum())} frame(s) hold fewer than {min_markers} of the {len(used)} weighted markers, "
        f"too few to solve IK: frames {', '.join(spans)}; markers missing there: {', '.join(absent) or 'none'}"
    )


def frames_with_markers(
    markers_m, labels: Sequence[str], min_markers: int = 3, root_markers: Sequence[str] = ()
) -> np.ndarray:
    """Frames that IK can solve: ``min_markers`` markers present, enough of them on the root body, one off it.

    The body jointed to the ground (the pelvis) carries every other body: it
    is placed by its own markers, of which a frame must hold ``min_markers``
    (three fix a rigid body), or all of them when the marker set has fewer.
    Otherwise the pelvis pose is left to the limb markers and the joint
    angles take up its error (a subject entering or leaving the capture
    volume with a thigh marker in view gives hip angles off by tens of
    degrees).

    Parameters
    ----------
    markers_m : array_like
        Shape (n_frames, n_markers, 3), metres, NaN where missing: the
        weighted markers only.
    labels : sequence of str
        One name per marker.
    min_markers : int
        Least number of markers present (the rule of :func:`require_markers_per_frame`).
    root_markers : sequence of str
        Markers on the body jointed to the ground (the pelvis); a frame whose
        present markers all sit there determines no joint angle. Empty: the
        root body is not checked (only the count and nothing else).

    Returns
    -------
    numpy.ndarray of bool
        Shape (n_frames,): True where the frame can be solved.
    """
    X = np.asarray(markers_m, dtype=float)
    labels = [str(lab) for lab in labels]
    if X.ndim != 3 or X.shape[2] != 3 or X.shape[1] != len(labels):
        raise LoperInputError(f"markers_m must have shape (n_frames, {len(labels)}, 3), got {X.shape}")
    present = np.all(np.isfinite(X), axis=2)
    root = np.array([lab in set(root_markers) for lab in labels], dtype=bool)
    enough = present.sum(axis=1) >= min_markers
    if not root.any():
        return enough
    placed = present[:, root].sum(axis=1) >= min(min_markers, int(root.sum()))
    return enough & placed & present[:, ~root].any(axis=1)


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
    from scipy.spatial.transform import Rotation

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


def lab_up(rotation_deg: Sequence[float]) -> np.ndarray:
    """The lab's up direction: the unit vector (lab frame) that :func:`rotate_markers` turns into the model's +Y.

    OpenSim's model frame is Y-up (:data:`MODEL_UP`), so the lab's up is
    ``R.T @ (0, 1, 0)`` for the lab-to-model rotation ``R`` of
    ``rotation_deg`` (the configuration's ``markers.lab_to_model_rotation_deg``).
    Components smaller than 1e-12 in magnitude (round-off of the quarter
    turns' sines and cosines) are set to 0 and the vector normalised again,
    so that ``(-90, 0, 0)`` (a Z-up lab) gives exactly :data:`loper_analysis.constants.LAB_Z_UP` and
    ``(0, 0, 0)`` (a Y-up lab such as BTS) exactly ``(0, 1, 0)``.

    Parameters
    ----------
    rotation_deg : sequence of float
        Three finite angles (degrees) about X, Y, Z, as :func:`rotate_markers`.

    Returns
    -------
    numpy.ndarray
        Shape (3,), unit vector, lab frame.

    Raises
    ------
    LoperInputError
        If ``rotation_deg`` is not 3 finite numbers.
    """
    up = rotate_markers(np.eye(3), rotation_deg)[:, 1]  # the identity rotated is R.T; R.T @ e_y is its column 1
    up[np.abs(up) < _AXIS_ROUND_OFF] = 0.0
    return up / np.linalg.norm(up)
