"""Gait events from the treadmill's vertical ground reaction force (their strides: :mod:`loper_analysis.gait.strides`).

* :func:`gait_events` - heel strikes and toe-offs from one belt's vertical
  force, with hysteresis and minimum phase durations;
* :func:`load_transitions` - the hysteresis itself (loading and unloading
  samples of any vertical force), shared with :mod:`loper_analysis.gait.contacts`;
* :func:`flagged_contacts` - how many flagged contacts an event table holds;
* :func:`stance_heels` - for each stance of a belt, whether the heel of that
  side's foot was the lower one: the check that the belts' channels carry the
  feet they are named after.

Time is in s, force in N. Side, event and phase names are those of
:mod:`loper_analysis.constants`.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from loper_analysis.checks import number, time_vector, where
from loper_analysis.checks import side as check_side
from loper_analysis.constants import FLAGGED_EVENTS
from loper_analysis.errors import LoperInputError

__all__ = [
    "EVENT_COLUMNS",
    "STANCE_HEEL_COLUMNS",
    "load_transitions",
    "gait_events",
    "flagged_contacts",
    "stance_heels",
]

logger = logging.getLogger(__name__)

#: Columns of the event table.
EVENT_COLUMNS: tuple[str, ...] = ("side", "event", "time_s", "sample")
#: Heel strike: the vertical force rises through this (N; config ``events.threshold_on_n``) ...
THRESHOLD_ON_N: float = 50.0
#: ... toe-off: it falls through this (N; ``events.threshold_off_n``): a hysteresis.
THRESHOLD_OFF_N: float = 20.0
#: Shorter stances (s; ``events.min_stance_s``) ...
MIN_STANCE_S: float = 0.2
#: ... and swings (s; ``events.min_swing_s``) are noise.
MIN_SWING_S: float = 0.2
#: Columns of :func:`stance_heels`.
STANCE_HEEL_COLUMNS: tuple[str, ...] = ("side", "heel_strike_s", "toe_off_s", "own_heel_lower_m", "own_heel_lower")
_HS, _TO = 1, 0  # state codes: 1 = loaded (stance), 0 = unloaded (swing)


def _hysteresis_events(force: np.ndarray, on: float, off: float) -> tuple[np.ndarray, np.ndarray]:
    """Samples and kinds (1 = heel strike, 0 = toe-off) of the state changes of the hysteresis."""
    n = force.size
    state = np.full(n, -1, dtype=np.int8)
    state[force <= off] = _TO
    state[force >= on] = _HS  # on > off: the two sets are disjoint
    last = np.where(state >= 0, np.arange(n), -1)
    np.maximum.accumulate(last, out=last)
    held = np.where(last >= 0, state[np.maximum(last, 0)], -1)  # state carried through the dead band
    change = np.flatnonzero((held[1:] != held[:-1]) & (held[:-1] >= 0)) + 1
    return change, held[change].astype(np.int8)


def _drop_short_periods(
    samples: np.ndarray, kinds: np.ndarray, time: np.ndarray, min_stance_s: float, min_swing_s: float
) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Remove, shortest first, each stance or swing period shorter than its minimum (both bounding events)."""
    dropped: list[dict] = []
    while samples.size >= 2:
        t = time[samples]
        duration = np.diff(t)
        minimum = np.where(kinds[:-1] == _HS, min_stance_s, min_swing_s)
        short = np.flatnonzero(duration < minimum)
        if not short.size:
            break
        i = short[np.argmin(duration[short])]
        dropped.append(
            {
                "phase": "stance" if kinds[i] == _HS else "swing",
                "start_s": float(t[i]),
                "end_s": float(t[i + 1]),
                "duration_s": float(duration[i]),
                "start_sample": int(samples[i]),
                "end_sample": int(samples[i + 1]),
            }
        )
        samples = np.delete(samples, [i, i + 1])
        kinds = np.delete(kinds, [i, i + 1])
    return samples, kinds, dropped


def load_transitions(
    time_s,
    vertical_force_n,
    threshold_on_n: float = THRESHOLD_ON_N,
    threshold_off_n: float = THRESHOLD_OFF_N,
    min_stance_s: float = MIN_STANCE_S,
    min_swing_s: float = MIN_SWING_S,
    source: str = "",
) -> tuple[np.ndarray, np.ndarray, list[dict]]:
    """Loading and unloading samples of one vertical force: the hysteresis of :func:`gait_events`.

    A sample with force ``>= threshold_on_n`` sets the state "loaded", a
    sample with force ``<= threshold_off_n`` sets "unloaded"; samples in
    between keep the state. A transition is the first sample of a new state;
    the state a trial starts in (or reaches first from the dead band) is not a
    transition. Loaded (unloaded) periods shorter than ``min_stance_s``
    (``min_swing_s``) are removed with both bounding transitions, shortest
    first, until none remains; the periods before the first and after the
    last transition are never judged.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    vertical_force_n : array_like, shape (n_samples,)
        Vertical force in N (above the unloaded level); must be finite.
    threshold_on_n, threshold_off_n : float
        Loading and unloading thresholds in N; ``threshold_on_n > threshold_off_n``.
    min_stance_s, min_swing_s : float
        Shortest accepted loaded and unloaded period in s (>= 0).
    source : str
        Name of the trial or signal, quoted in error messages.

    Returns
    -------
    samples : numpy.ndarray of int64, shape (n_transitions,)
        Indices into ``time_s`` of the transitions, increasing; loading and
        unloading alternate.
    loading : numpy.ndarray of bool, shape (n_transitions,)
        True where the transition is a loading (force reached
        ``threshold_on_n``), False for an unloading.
    dropped : list of dict
        The removed periods: ``phase`` (``stance`` | ``swing``), ``start_s``,
        ``end_s``, ``duration_s``, ``start_sample``, ``end_sample``.

    Raises
    ------
    LoperInputError
        Non-finite or non-increasing time, non-finite force (the first sample
        is named), mismatched lengths, ``threshold_on_n <= threshold_off_n``
        or negative minimum durations.
    """
    t = time_vector(time_s, source)
    f = np.asarray(vertical_force_n, dtype=float)
    if f.ndim != 1 or f.size != t.size:
        raise LoperInputError(f"{where(source)}vertical_force_n has shape {f.shape}; time_s has {t.size} samples")
    bad = np.flatnonzero(~np.isfinite(f))
    if bad.size:
        raise LoperInputError(f"{where(source)}vertical_force_n is not finite at sample {bad[0]}: {f[bad[0]]}")
    on = number("threshold_on_n", threshold_on_n, source)
    off = number("threshold_off_n", threshold_off_n, source)
    if on <= off:
        raise LoperInputError(
            f"{where(source)}threshold_on_n ({on} N) must exceed threshold_off_n ({off} N) for hysteresis"
        )
    min_stance = number("min_stance_s", min_stance_s, source, minimum=0.0)
    min_swing = number("min_swing_s", min_swing_s, source, minimum=0.0)
    samples, kinds = _hysteresis_events(f, on, off)
    samples, kinds, dropped = _drop_short_periods(samples, kinds, t, min_stance, min_swing)
    return samples.astype(np.int64), kinds == _HS, dropped


def gait_events(
    time_s,
    vertical_force_n,
    side: str,
    threshold_on_n: float = THRESHOLD_ON_N,
    threshold_off_n: float = THRESHOLD_OFF_N,
    min_stance_s: float = MIN_STANCE_S,
    min_swing_s: float = MIN_SWING_S,
    source: str = "",
) -> pd.DataFrame:
    """Heel strikes and toe-offs from one belt's vertical ground-reaction force.

    A two-threshold (hysteresis) detector. A sample with force
    ``>= threshold_on_n`` sets the state "loaded", a sample with force
    ``<= threshold_off_n`` sets "unloaded"; samples in between keep the state.

    * **Heel strike** = the first sample with force ``>= threshold_on_n``
      after the force was last ``<= threshold_off_n``.
    * **Toe-off** = the first sample with force ``<= threshold_off_n`` after
      the force was last ``>= threshold_on_n``.

    The event time is ``time_s`` at that sample (no interpolation between
    samples). A trial starting inside the dead band has an unknown state until
    the first threshold is reached; that first reach is not an event.

    Periods shorter than the minimum durations are noise blips: a stance
    (heel strike -> toe-off) shorter than ``min_stance_s`` or a swing (toe-off
    -> heel strike) shorter than ``min_swing_s`` is removed with both bounding
    events, shortest first, until none remains (the surrounding periods
    merge). The periods before the first and after the last event are
    incomplete and never judged. Removed periods are logged (INFO) and listed
    in ``attrs["dropped"]``.

    Parameters
    ----------
    time_s : array_like, shape (n_samples,)
        Sample times in s, finite and strictly increasing.
    vertical_force_n : array_like, shape (n_samples,)
        Vertical ground-reaction force of the belt under ``side``, in N; must be finite.
    side : {"left", "right"}
    threshold_on_n, threshold_off_n : float
        Loading and unloading thresholds in N; ``threshold_on_n > threshold_off_n``.
    min_stance_s, min_swing_s : float
        Shortest accepted stance and swing period in s (>= 0).
    source : str
        Name of the trial or file, quoted in error and log messages.

    Returns
    -------
    pandas.DataFrame
        One row per event, in time order: ``side``, ``event``
        (``heel_strike`` | ``toe_off``), ``time_s`` (s), ``sample`` (int,
        index into ``time_s``). Heel strikes and toe-offs alternate.
        ``attrs``: ``source``, ``side``, the thresholds and minimum
        durations, and ``dropped`` - a list of dicts (``phase``, ``start_s``,
        ``end_s``, ``duration_s``, ``start_sample``, ``end_sample``).

    Raises
    ------
    LoperInputError
        Non-finite or non-increasing time, non-finite force (the first sample
        is named), mismatched lengths, ``threshold_on_n <= threshold_off_n``,
        negative minimum durations, an unknown side, or no event at all.
    """
    side = check_side(side, source)
    t = time_vector(time_s, source)
    samples, loading, dropped = load_transitions(
        t, vertical_force_n, threshold_on_n, threshold_off_n, min_stance_s, min_swing_s, source
    )
    f = np.asarray(vertical_force_n, dtype=float)
    on, off = float(threshold_on_n), float(threshold_off_n)  # checked by load_transitions
    for d in dropped:
        logger.info(
            "%s%s side: dropped a %.3f s %s period (%.3f-%.3f s), shorter than the minimum",
            where(source),
            side,
            d["duration_s"],
            d["phase"],
            d["start_s"],
            d["end_s"],
        )
    if not samples.size:
        raise LoperInputError(
            f"{where(source)}no gait event in vertical_force_n ({side} side): the force never crosses "
            f"{off} N and {on} N in turn (range {f.min():.1f} .. {f.max():.1f} N)"
        )
    events = pd.DataFrame(
        {
            "side": side,
            "event": np.where(loading, "heel_strike", "toe_off"),
            "time_s": t[samples],
            "sample": samples.astype(np.int64),
        }
    )
    events.attrs.update(
        {
            "source": source,
            "side": side,
            "threshold_on_n": on,
            "threshold_off_n": off,
            "min_stance_s": float(min_stance_s),
            "min_swing_s": float(min_swing_s),
            "dropped": dropped,
        }
    )
    return events


def flagged_contacts(events: pd.DataFrame, side: str | None = None) -> int:
    """Number of flagged contacts in an event table (its ``flagged_start`` rows).

    Parameters
    ----------
    events : pandas.DataFrame
        Columns ``side``, ``event``, ``time_s``
        (:func:`loper_analysis.gait.contacts.contact_events`); tables from
        :func:`gait_events` hold none.
    side : {"left", "right"} or None
        Count the contacts flagged for that side's strides (a contact whose
        foot is unknown or both feet counts for both sides); None: every
        flagged contact once (rows of one contact share their start time).

    Returns
    -------
    int
    """
    source = str(events.attrs.get("source", "")) if isinstance(events, pd.DataFrame) else ""
    if not isinstance(events, pd.DataFrame) or not {"side", "event", "time_s"} <= set(events.columns):
        raise LoperInputError(f"{where(source)}events must be a table with columns side, event, time_s")
    starts = events[events["event"] == FLAGGED_EVENTS[0]]
    if side is None:
        return int(starts["time_s"].nunique())
    return int((starts["side"] == check_side(side, source)).sum())


def stance_heels(events: pd.DataFrame, time_s, heel_height_m) -> pd.DataFrame:
    """For each stance of each belt, how much lower that side's heel was than the other's at mid-stance.

    On a treadmill the foot on a belt stands while the other foot swings: over
    the middle half of a stance (heel strike to the side's next toe-off) the
    standing heel is the lower one. Belt channels swapped between the feet
    give stances in which the other heel is the lower.

    Parameters
    ----------
    events : pandas.DataFrame
        Columns ``side``, ``event``, ``time_s`` (:func:`gait_events` of both belts).
    time_s : array_like, shape (n,)
        Marker frame times, s.
    heel_height_m : mapping
        ``{"left": h, "right": h}``: each heel marker's height along the
        vertical, m, shape (n,); NaN where the marker is missing.

    Returns
    -------
    pandas.DataFrame
        One row per stance (:data:`STANCE_HEEL_COLUMNS`): ``side``,
        ``heel_strike_s``, ``toe_off_s``, ``own_heel_lower_m`` (the other
        heel's height minus this side's, mean over the middle half of the
        stance, m; NaN when no frame there has both heels) and
        ``own_heel_lower`` (``own_heel_lower_m > 0``; False when NaN).
    """
    source = str(events.attrs.get("source", "")) if isinstance(events, pd.DataFrame) else ""
    t = time_vector(time_s, source, item="frame")
    heights = {s: np.asarray(heel_height_m[s], dtype=float) for s in ("left", "right")}
    for s, h in heights.items():
        if h.shape != t.shape:
            raise LoperInputError(f"{where(source)}heel_height_m[{s!r}]: shape {h.shape}, expected {t.shape}")
    rows = []
    for side, other in (("left", "right"), ("right", "left")):
        mine = events[events["side"] == side]
        kind, when = mine["event"].to_numpy(), mine["time_s"].to_numpy(dtype=float)
        hs, to = np.sort(when[kind == "heel_strike"]), np.sort(when[kind == "toe_off"])
        for start in hs:
            later = to[to > start]
            if later.size == 0:
                continue
            end = later[0]
            quarter = 0.25 * (end - start)
            inside = (t >= start + quarter) & (t <= end - quarter)
            gap = heights[other][inside] - heights[side][inside]
            gap = gap[np.isfinite(gap)]
            lower = float(gap.mean()) if gap.size else np.nan
            rows.append((side, float(start), float(end), lower, bool(lower > 0)))
    table = pd.DataFrame(rows, columns=list(STANCE_HEEL_COLUMNS))
    return table.sort_values("heel_strike_s", kind="stable", ignore_index=True)
