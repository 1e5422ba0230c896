"""The time-normalised cycles of a trial's strides as one table (:func:`loper_analysis.gait.strides.stride_tables`).

Times in s, angles in rad, force in N.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from loper_analysis.constants import PHASES
from loper_analysis.gait.resampling import normalise

__all__ = ["cycles_table"]


def cycles_table(
    time_s: np.ndarray,
    angles_rad: np.ndarray,
    columns: Sequence[str],
    strides: pd.DataFrame,
    n_points: int,
    force_n: np.ndarray | None,
    sources: Mapping[str, str],
) -> pd.DataFrame:
    """The cycles of every stride, stance and swing, each normalised to ``n_points`` samples.

    Parameters
    ----------
    time_s : numpy.ndarray, shape (n_frames,)
        Frame times in s.
    angles_rad : numpy.ndarray, shape (n_frames, len(columns))
        Joint angles in rad, named ``columns``.
    strides : pandas.DataFrame
        Stride table with ``stride``, ``heel_strike_s``, ``toe_off_s``, ``end_s`` (s).
    n_points : int
        Samples per normalised cycle.
    force_n : numpy.ndarray, shape (n_frames,), or None
        Interaction force in N on the same frames; None: no force column.
    sources : mapping
        Names of the ``angles`` and ``force``, quoted in messages.

    Returns
    -------
    pandas.DataFrame
        One row per stride x phase x sample, phases in :data:`loper_analysis.constants.PHASES` order:
        ``stride``, ``phase``, ``point``, ``percent``, the angles (rad) and, with a force, ``force_n`` (N).
    """
    cycles = []
    for phase in PHASES:
        arr = normalise(time_s, angles_rad, strides, phase, n_points, source=sources["angles"])
        block = {
            "stride": np.repeat(strides["stride"].to_numpy(), n_points),
            "phase": phase,
            "point": np.tile(np.arange(n_points), len(strides)),
            "percent": np.tile(np.linspace(0.0, 100.0, n_points), len(strides)),
        }
        for i, c in enumerate(columns):
            block[c] = arr[:, :, i].ravel()
        if force_n is not None:
            block["force_n"] = normalise(time_s, force_n, strides, phase, n_points, source=sources["force"]).ravel()
        cycles.append(pd.DataFrame(block))
    return pd.concat(cycles, ignore_index=True)
