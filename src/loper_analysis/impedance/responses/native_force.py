"""The rod force of perturbed and matched unperturbed strides at the robot log's own rate.

The 128 Hz frames cut a pulse's 10 ms edges short; the identification takes
the force from the robot's samples instead (``docs/identification.md``). The
load cell's force (low-passed, on the mocap clock:
``results/events/{subject}/{trial}.force_native.tsv``) is linearly
interpolated on a relative grid at the robot rate around each onset and
anchor, and multiplied by the rod direction from the brace markers, whose
frames are linearly interpolated to the same times and normalised.

With a second rod at the shank the direction has four columns (the thigh rod's x/y, then the shank rod's) and
the tables hold that rod's load cell too (``shank_force_measured_n``): each rod's force is formed the same way
and the vectors stand side by side, (..., 4) in N.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.checks import require_columns, where
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s

__all__ = [
    "ROD_FORCE_COLUMNS",
    "native_force_rate_hz",
    "native_force_windows",
    "force_vectors",
    "finite_spans",
    "rod_magnitudes",
]

#: The load cells' columns, one per rod: the thigh rod's, then a second rod's at the shank.
ROD_FORCE_COLUMNS: tuple[str, ...] = ("force_measured_n", "shank_force_measured_n")


def rod_magnitudes(table: pd.DataFrame, direction, source: str = "") -> np.ndarray:
    """The load cells' forces (N) of the rods ``direction`` (n_frames, 2 per rod) points: (n,) for the thigh rod
    alone, (n, 2) with the shank rod (its column ``shank_force_measured_n`` must be in ``table``)."""
    n_rods = np.shape(direction)[-1] // 2
    if n_rods == 1:
        return require_columns(table, ROD_FORCE_COLUMNS[:1], source)["force_measured_n"].to_numpy(float)
    columns = ROD_FORCE_COLUMNS[:n_rods]
    return require_columns(table, columns, source)[list(columns)].to_numpy(float)


def native_force_rate_hz(native: pd.DataFrame, source: str = "") -> float:
    """The rate (Hz, rounded to a whole Hz) of a robot-rate force table (``time_s`` strictly increasing)."""
    t = require_columns(native, ("time_s", "force_measured_n"), source)["time_s"].to_numpy(float)
    d = np.diff(t)
    if t.size < 2 or not np.all(np.isfinite(t)) or np.any(d <= 0):
        raise LoperInputError(f"{where(source)}column 'time_s' must hold >= 2 finite, strictly increasing times")
    return float(round(1.0 / float(np.median(d))))


def force_vectors(targets, robot_time_s, magnitude_n, frame_time_s, direction) -> np.ndarray:
    """Rod-force vectors (N) at ``targets`` (s, any shape): the robot-rate magnitude ``magnitude_n`` (N; (n,),
    or (n, R) for R rods) at ``robot_time_s`` and the frames' rod ``direction`` (n_frames, 2 R) at
    ``frame_time_s``, both linearly interpolated, each rod's direction normalised. Shape
    ``targets.shape + (2 R,)``."""
    magnitude = np.asarray(magnitude_n, dtype=float)
    rods = [magnitude] if magnitude.ndim == 1 else [magnitude[:, r] for r in range(magnitude.shape[1])]
    out = []
    for r, mag in enumerate(rods):
        m = np.interp(targets, robot_time_s, mag)
        d = np.stack([np.interp(targets, frame_time_s, direction[:, 2 * r + j]) for j in range(2)], axis=-1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        out.append(m[..., None] * d)
    return out[0] if len(out) == 1 else np.concatenate(out, axis=-1)


def finite_spans(time_s, values, lo_s, hi_s) -> np.ndarray:
    """Whether every sample of ``values`` at ``time_s`` (sorted, s) within ``lo_s[i] .. hi_s[i]`` (s, ends
    included) is finite: (n,) bool, one count of non-finite samples per span instead of a mask per span."""
    bad = np.concatenate([[0], np.cumsum(~np.isfinite(np.asarray(values, dtype=float)))])
    a = np.searchsorted(time_s, np.asarray(lo_s, dtype=float), side="left")
    b = np.searchsorted(time_s, np.asarray(hi_s, dtype=float), side="right")
    return bad[b] == bad[a]


def native_force_windows(
    frame_time_s,
    direction,
    native: pd.DataFrame,
    matches: pd.DataFrame,
    start_s: float,
    end_s: float,
    rate_hz: float,
    source: str = "",
) -> tuple[np.ndarray, np.ndarray]:
    """Perturbed and matched unperturbed rod-force vectors at the robot rate.

    Parameters
    ----------
    frame_time_s : (n_frames,) frame times (s) of ``direction``.
    direction : (n_frames, 2) unit vectors of the rod force (world x/y); (n_frames, 4) with a second rod.
    native : DataFrame with ``time_s`` (s, mocap clock) and ``force_measured_n`` (N) at the robot's samples
    (and ``shank_force_measured_n`` with a second rod).
    matches : ``onset_s`` and ``matched_anchor_s`` (s) per pair
    (:func:`~loper_analysis.impedance.responses.match_unperturbed`).
    start_s, end_s : the window relative to the onset (s), as for
    :func:`~loper_analysis.impedance.responses.paired_windows`.
    rate_hz : grid rate (Hz), e.g. :func:`native_force_rate_hz`.
    source : names the trial in messages.

    Returns
    -------
    (perturbed, unperturbed), each (n_pairs, n_grid, 2) in N ((..., 4) with a second rod) on the grid
    ``loper_analysis.gait.resampling.window_times_s(-start_s, end_s, rate_hz)``.

    Raises
    ------
    LoperInputError
        A window outside the force table's span or the frames, non-finite force in a window.
    """
    table = require_columns(native, ("time_s", "force_measured_n"), source)
    tn = table["time_s"].to_numpy(float)
    fm = rod_magnitudes(table, direction, source)
    fm_all = fm if fm.ndim == 1 else fm.sum(axis=1)  # non-finite where any rod's is
    tf = np.asarray(frame_time_s, dtype=float)
    u = np.asarray(direction, dtype=float)
    grid = window_times_s(-start_s, end_s, rate_hz)
    out = []
    for what, col in (("perturbed", "onset_s"), ("unperturbed", "matched_anchor_s")):
        anchors = matches[col].to_numpy(float)
        targets = anchors[:, None] + grid
        lo, hi = targets[:, 0], targets[:, -1]
        ok = (lo >= max(tn[0], tf[0]) - 1e-9) & (hi <= min(tn[-1], tf[-1]) + 1e-9)
        ok &= finite_spans(tn, fm_all, lo - 1.0 / rate_hz, hi + 1.0 / rate_hz)
        for i in np.flatnonzero(~ok)[:1]:
            raise LoperInputError(
                f"{where(source)}the {what} force window of stride {matches['stride'].iloc[i]} "
                f"({lo[i]:.4f} .. {hi[i]:.4f} s) leaves the finite force at the robot rate "
                f"({tn[0]:.4f} .. {tn[-1]:.4f} s) or the marker frames ({tf[0]:.4f} .. {tf[-1]:.4f} s)"
            )
        out.append(force_vectors(targets, tn, fm, tf, u))
    return out[0], out[1]
