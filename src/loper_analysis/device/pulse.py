"""The shape of a measured LOPER force pulse: rise time and overshoot of the controlled robot.

A commanded rectangle (``force_n`` for ``duration_s``) reaches the leg as the
robot's step response to its switching on, minus the same response to its
switching off. The step response is that of a second-order system whose
damping ratio gives the overshoot and whose natural frequency gives the 10-90 %
rise time, e.g. the study's 10 ms and 30.5 % (:data:`loper_analysis.reference.STUDY_DEVICE`).
The impulse of the pulse is ``force_n * duration_s`` (the two step responses
settle to the same level), however fast or slow its edges.

:func:`find_force_pulses` finds such pulses in a measured force without the
robot's perturbation flag: tens of newtons for tens to hundreds of
milliseconds, against the few newtons of the minimal-impedance force.
"""

from __future__ import annotations

import numpy as np

from loper_analysis.checks import positive
from loper_analysis.errors import LoperInputError

__all__ = [
    "second_order_parameters",
    "step_response",
    "pulse_force",
    "find_force_pulses",
    "PULSE_MIN_DURATION_S",
    "PULSE_MAX_DURATION_S",
    "PULSE_MIN_THRESHOLD_N",
    "PULSE_THRESHOLD_SDS",
]

#: Shortest and longest run above the threshold that counts as a force pulse, s (the study's pulse: 0.1 s; the
#: robot's start-up transient rings in half-periods of about 10 ms).
PULSE_MIN_DURATION_S = 0.02
PULSE_MAX_DURATION_S = 0.5
#: Detection threshold on |force - baseline|: at least this many newtons ...
PULSE_MIN_THRESHOLD_N = 15.0
#: ... and at least this many robust standard deviations (1.4826 x MAD) of the force about its baseline.
PULSE_THRESHOLD_SDS = 8.0
#: Window of the running median that gives the baseline, s, and the blocks it runs over, s.
_BASELINE_WINDOW_S = 1.0
_BLOCK_S = 0.01


def second_order_parameters(rise_time_s: float, overshoot_pct: float) -> tuple[float, float]:
    """Damping ratio (-) and natural frequency (rad/s) of a step response with this rise time (10-90 %, s) and
    overshoot (%).

    Raises
    ------
    LoperInputError
        A rise time that is not positive, an overshoot outside 0 < overshoot < 100 %.
    """
    tr = positive("rise_time_s", rise_time_s)
    if not 0.0 < overshoot_pct < 100.0:
        raise LoperInputError(f"overshoot_pct must lie in 0 .. 100 % (exclusive), got {overshoot_pct}")
    lo = np.log(overshoot_pct / 100.0)
    zeta = float(-lo / np.sqrt(np.pi**2 + lo**2))
    # rise time of the unit-frequency response: first crossings of 0.1 and 0.9 (it rises monotonically to its peak)
    tau = np.linspace(0.0, np.pi / np.sqrt(1.0 - zeta**2), 20001)
    y = _unit_step(tau, zeta)
    tr_unit = float(np.interp(0.9, y, tau) - np.interp(0.1, y, tau))
    return zeta, tr_unit / tr


def _unit_step(tau: np.ndarray, zeta: float) -> np.ndarray:
    wd = np.sqrt(1.0 - zeta**2)
    tau = np.maximum(tau, 0.0)
    return 1.0 - np.exp(-zeta * tau) * (np.cos(wd * tau) + zeta / wd * np.sin(wd * tau))


def step_response(time_s, rise_time_s: float, overshoot_pct: float) -> np.ndarray:
    """Unit step response (n,) at ``time_s`` (s after the step; 0 before it)."""
    zeta, wn = second_order_parameters(rise_time_s, overshoot_pct)
    t = np.asarray(time_s, dtype=float)
    return np.where(t > 0.0, _unit_step(wn * t, zeta), 0.0)


def pulse_force(
    time_s, onset_s: float, duration_s: float, force_n: float, rise_time_s: float, overshoot_pct: float
) -> np.ndarray:
    """Force (n,) in N of a pulse commanded from ``onset_s`` for ``duration_s`` (s), as the robot delivers it.

    ``force_n * (y(t - onset_s) - y(t - onset_s - duration_s))`` with ``y`` the
    :func:`step_response` of ``rise_time_s`` (10-90 %, s) and ``overshoot_pct`` (%).
    """
    duration = positive("duration_s", duration_s)
    t = np.asarray(time_s, dtype=float)
    return force_n * (
        step_response(t - onset_s, rise_time_s, overshoot_pct)
        - step_response(t - onset_s - duration, rise_time_s, overshoot_pct)
    )


def find_force_pulses(
    force_n,
    sample_rate_hz: float,
    min_duration_s: float = PULSE_MIN_DURATION_S,
    max_duration_s: float = PULSE_MAX_DURATION_S,
    threshold_n: float | None = None,
    source: str = "",
) -> np.ndarray:
    """Force pulses in a measured force: runs far from its slowly varying baseline, of pulse-like duration.

    The baseline is a running median over ``_BASELINE_WINDOW_S`` (1 s) of 10 ms
    block means (a 0.1 s pulse barely moves it); a pulse is a run of samples
    whose ``|force - baseline|`` exceeds the threshold for between
    ``min_duration_s`` and ``max_duration_s``. The default threshold is the
    larger of :data:`PULSE_MIN_THRESHOLD_N` and :data:`PULSE_THRESHOLD_SDS`
    robust standard deviations of ``force - baseline``: a 40 N pulse stands
    out of a minimal-impedance force of a few newtons, the gait's own
    force does not, nor does the robot's start-up transient (shorter runs).

    Parameters
    ----------
    force_n : array_like, shape (n,)
        Force, N, sampled uniformly (e.g. the low-passed load cell at the
        robot rate); NaN samples never belong to a pulse.
    sample_rate_hz : float
        Sampling rate, Hz.
    min_duration_s, max_duration_s : float
        Accepted duration of a pulse above the threshold, s.
    threshold_n : float, optional
        Threshold on ``|force - baseline|``, N (default: see above).
    source : str
        Names the signal in error messages.

    Returns
    -------
    numpy.ndarray, shape (n_pulses, 3)
        Per pulse: first sample, one past its last sample (both as float
        indices) and its signed peak of ``force - baseline``, N.

    Raises
    ------
    LoperInputError
        Not 1-D, a non-positive rate or durations, ``max_duration_s <= min_duration_s``.
    """
    src = source or "force"
    rate = positive("sample_rate_hz", sample_rate_hz, src)
    lo = positive("min_duration_s", min_duration_s, src)
    hi = positive("max_duration_s", max_duration_s, src)
    if not hi > lo:
        raise LoperInputError(f"{src}: max_duration_s ({hi}) must exceed min_duration_s ({lo})")
    f = np.asarray(force_n, dtype=float)
    if f.ndim != 1:
        raise LoperInputError(f"{src}: the force must be 1-D, got shape {f.shape}")
    empty = np.empty((0, 3))
    finite = np.isfinite(f)
    if finite.sum() < 2:
        return empty
    resid = f - _baseline(np.where(finite, f, np.nan), rate)
    resid[~np.isfinite(resid)] = 0.0
    if threshold_n is None:
        sd = 1.4826 * float(np.median(np.abs(resid[finite] - np.median(resid[finite]))))
        thr = max(PULSE_MIN_THRESHOLD_N, PULSE_THRESHOLD_SDS * sd)
    else:
        thr = positive("threshold_n", threshold_n, src)
    above = np.concatenate(([False], np.abs(resid) > thr, [False]))
    edges = np.flatnonzero(np.diff(above.astype(np.int8)))
    starts, stops = edges[0::2], edges[1::2]
    duration = (stops - starts) / rate
    keep = (duration >= lo) & (duration <= hi)
    starts, stops = starts[keep], stops[keep]
    if not starts.size:
        return empty
    peaks = np.array([resid[a + int(np.argmax(np.abs(resid[a:b])))] for a, b in zip(starts, stops)])
    return np.column_stack([starts, stops, peaks]).astype(float)


def _baseline(f: np.ndarray, rate: float) -> np.ndarray:
    """Running median (about ``_BASELINE_WINDOW_S``) of block means (``_BLOCK_S``) of ``f``, at every sample."""
    from scipy.ndimage import median_filter

    n = f.size
    block = max(1, int(round(_BLOCK_S * rate)))
    nb = n // block
    if nb < 3:
        return np.full(n, np.nanmedian(f))
    means = np.nanmean(f[: nb * block].reshape(nb, block), axis=1)
    means = np.where(np.isfinite(means), means, np.nanmedian(means))
    size = 2 * int(round(0.5 * _BASELINE_WINDOW_S / (block / rate))) + 1
    smooth = median_filter(means, size=min(size, nb - 1 + nb % 2), mode="nearest")  # odd, at most nb
    centres = (np.arange(nb) + 0.5) * block - 0.5
    return np.interp(np.arange(n), centres, smooth)
