"""Loaded periods (contacts) of one force plate from its vertical force above the resting level.

* :func:`plate_contacts` - the contacts of one plate, with the hysteresis and minimum durations of
  :func:`loper_analysis.gait.events.load_transitions`; those cut by the start or end of the recording marked
  ``incomplete``.

Time in s, force in N. ``docs/events.md`` explains the rules.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.checks import time_vector
from loper_analysis.gait.events import (
    MIN_STANCE_S,
    MIN_SWING_S,
    THRESHOLD_OFF_N,
    THRESHOLD_ON_N,
    load_transitions,
)

__all__ = ["PLATE_CONTACT_COLUMNS", "plate_contacts"]

#: Columns of :func:`plate_contacts`.
PLATE_CONTACT_COLUMNS: tuple[str, ...] = ("contact", "start_sample", "end_sample", "start_s", "end_s", "incomplete")


def plate_contacts(
    time_s,
    vertical_force_n,
    threshold_on_n: float = THRESHOLD_ON_N,
    threshold_off_n: float = THRESHOLD_OFF_N,
    min_stance_s: float = MIN_STANCE_S,
    min_swing_s: float = MIN_SWING_S,
    source: str = "",
) -> pd.DataFrame:
    """Loaded periods (contacts) of one plate from its vertical force above the resting level.

    A contact starts at the first sample with force ``>= threshold_on_n``
    (the heel strike of :func:`loper_analysis.gait.events.gait_events`) and ends at
    the first later sample with force ``<= threshold_off_n`` (the toe-off),
    with the same hysteresis and minimum durations. A plate loaded when the
    trial starts (or reaching the loaded state from the dead band first) gives
    a contact from sample 0, one still loaded at the end a contact to the last
    sample; both are ``incomplete``. A plate never loaded gives no row.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    vertical_force_n : array_like, shape (n_samples,)
        Vertical force in N above the plate's resting level; finite.
    threshold_on_n, threshold_off_n : float
        Loading and unloading thresholds in N above the resting level; on > off.
    min_stance_s, min_swing_s : float
        Shortest accepted loaded and unloaded period in s.
    source : str
        Name of the trial and plate, quoted in messages.

    Returns
    -------
    pandas.DataFrame
        One row per contact in time order (:data:`PLATE_CONTACT_COLUMNS`):
        ``contact`` (0, 1, ...), ``start_sample``, ``end_sample`` (int,
        indices into ``time_s``), ``start_s``, ``end_s`` (s), ``incomplete``
        (bool). ``attrs["dropped"]``: the periods removed as too short.

    Raises
    ------
    LoperInputError
        As :func:`loper_analysis.gait.events.load_transitions`.
    """
    t = time_vector(time_s, source)
    samples, loading, dropped = load_transitions(
        t, vertical_force_n, threshold_on_n, threshold_off_n, min_stance_s, min_swing_s, source
    )
    starts, ends = list(samples[loading]), list(samples[~loading])
    open_start = bool(samples.size) and not loading[0]
    if not samples.size:  # no transition left: loaded throughout or never loaded
        open_start = _loaded_at_end(
            np.asarray(vertical_force_n, dtype=float), float(threshold_on_n), float(threshold_off_n)
        )
    if open_start:
        starts.insert(0, 0)
    open_end = len(starts) > len(ends)
    if open_end:
        ends.append(t.size - 1)
    start = np.asarray(starts, dtype=np.int64)
    end = np.asarray(ends, dtype=np.int64)
    incomplete = np.zeros(start.size, dtype=bool)
    if start.size:
        incomplete[0] |= open_start
        incomplete[-1] |= open_end
    table = pd.DataFrame(
        {
            "contact": np.arange(start.size, dtype=np.int64),
            "start_sample": start,
            "end_sample": end,
            "start_s": t[start],
            "end_s": t[end],
            "incomplete": incomplete,
        },
        columns=list(PLATE_CONTACT_COLUMNS),
    )
    table.attrs["dropped"] = dropped
    return table


def _loaded_at_end(f: np.ndarray, on: float, off: float) -> bool:
    """Whether the hysteresis ends loaded: the force last reached ``on`` after it last fell to ``off``."""
    high, low = np.flatnonzero(f >= on), np.flatnonzero(f <= off)
    return bool(high.size) and (not low.size or high[-1] > low[-1])
