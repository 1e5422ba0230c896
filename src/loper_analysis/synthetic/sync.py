"""The robot's sync output in synthetic trials: pulses at pseudo-random intervals.

A pulse train with a fixed period cannot resolve an offset of whole periods
between the robot and the motion-capture clocks, so walking trials use a
train whose pulse-start intervals are drawn at random
(:func:`sync_pulse_starts`): a window of a few consecutive intervals then
occurs once only, and :func:`loper_analysis.device.clock_sync.clock_map` finds the
offset unambiguously.
"""

from __future__ import annotations

import math

import numpy as np

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError

__all__ = ["sync_pulse_starts", "pulse_train_at"]


def sync_pulse_starts(
    duration_s: float,
    seed: int | np.random.SeedSequence,
    min_interval_s: float = 0.5,
    max_interval_s: float = 1.5,
) -> np.ndarray:
    """Start times of the pseudo-random sync pulses, s on the robot clock.

    Intervals are drawn uniformly in [``min_interval_s``, ``max_interval_s``)
    from ``numpy.random.default_rng(seed)``; the first pulse starts one drawn
    interval after t = 0 (the record begins low). Pulses starting at or after
    ``duration_s`` are dropped. The draws of a longer train begin with those of
    a shorter one (same seed), so the train does not depend on where it is cut.

    With intervals spread over 1 s, two windows of 4 consecutive intervals agree
    within +-7.5 ms per interval with probability ~ (0.015)**4 ~ 5e-8: any 5
    consecutive edges identify their place in the train.

    Returns
    -------
    numpy.ndarray, shape (n_pulses,)
        Strictly increasing start times, s, in (0, duration_s).

    Raises
    ------
    LoperInputError
        Non-positive duration or interval, ``max_interval_s <= min_interval_s``
        (equal bounds would give a periodic, ambiguous train).
    """
    duration = positive("duration_s", duration_s)
    lo = positive("min_interval_s", min_interval_s)
    hi = positive("max_interval_s", max_interval_s)
    if not hi > lo:
        raise LoperInputError(
            f"max_interval_s ({max_interval_s}) must exceed min_interval_s ({min_interval_s}): "
            "equal intervals give a periodic train whose whole-period offset cannot be resolved"
        )
    rng = np.random.default_rng(seed)
    n = int(math.ceil(duration / lo)) + 1
    starts = np.cumsum(rng.uniform(lo, hi, n))
    return starts[starts < duration]


def pulse_train_at(time_s, starts_s, pulse_s: float = 0.01, level_v: float = 5.0) -> np.ndarray:
    """The sync output at arbitrary robot-clock times: ``level_v`` within a pulse, else 0 V.

    Parameters
    ----------
    time_s : array_like, shape (n,)
        Robot-clock times at which to sample, s.
    starts_s : array_like, shape (n_pulses,)
        Strictly increasing pulse start times, s (:func:`sync_pulse_starts`).
    pulse_s : float
        Pulse length, s; a time t is high if ``start <= t < start + pulse_s``.
    level_v : float
        High level, V.

    Returns
    -------
    numpy.ndarray, shape (n,)
        Sync voltage, V.
    """
    t = np.asarray(time_s, dtype=float)
    starts = np.asarray(starts_s, dtype=float)
    width = positive("pulse_s", pulse_s)
    if starts.ndim != 1 or (starts.size > 1 and np.any(np.diff(starts) <= 0)):
        raise LoperInputError("starts_s must be a 1-D strictly increasing array of pulse start times")
    if starts.size == 0:
        return np.zeros(t.shape)
    k = np.searchsorted(starts, t, side="right") - 1
    high = (k >= 0) & (t - starts[np.clip(k, 0, None)] < width)
    return np.where(high, float(level_v), 0.0)
