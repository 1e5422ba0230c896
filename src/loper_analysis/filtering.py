"""Zero-phase low-pass filtering of markers and forces (``docs/processing.md``, the filter)."""

from __future__ import annotations

import numpy as np

from .errors import LoperInputError

__all__ = ["lowpass", "lowpass_gain"]


def _design(sample_rate_hz: float, cutoff_hz: float, order: int):
    from scipy.signal import (
        butter,  # imported here: scipy.signal costs ~1 s, and most rules never filter
    )

    if not np.isfinite(sample_rate_hz) or sample_rate_hz <= 0:
        raise LoperInputError(f"sample_rate_hz must be positive, got {sample_rate_hz}")
    nyq = 0.5 * sample_rate_hz
    if not 0 < cutoff_hz < nyq:
        raise LoperInputError(f"cutoff_hz must lie in 0 .. {nyq} Hz (Nyquist of {sample_rate_hz} Hz), got {cutoff_hz}")
    if int(order) != order or order < 1:
        raise LoperInputError(f"order must be an integer >= 1, got {order}")
    return butter(int(order), cutoff_hz / nyq, output="sos")


def lowpass(signal, sample_rate_hz: float, cutoff_hz: float = 40.0, order: int = 4, axis: int = 0) -> np.ndarray:
    """Butterworth low-pass of ``order`` run forward and backward (zero phase).

    The forward-backward pass squares the magnitude response: the gain at
    ``cutoff_hz`` is 0.5 (-6 dB) and the roll-off that of order ``2 * order``
    (see :func:`lowpass_gain`). ``signal`` is an array sampled along ``axis``
    (e.g. (n_frames, n_markers, 3) markers in m, or (n_samples,) forces in N);
    it must be finite (fill marker gaps first). Returns a new array of the same
    shape.

    Raises
    ------
    LoperInputError
        Non-finite samples (the first is named), a cut-off at or above Nyquist,
        a signal too short for the filter's padding.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim == 0:
        raise LoperInputError("signal must have at least one dimension")
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        idx = tuple(int(i) for i in bad[0])
        raise LoperInputError(
            f"signal is not finite at sample {idx[axis]} (index {idx}): fill gaps before filtering"
        )
    sos = _design(sample_rate_hz, cutoff_hz, order)
    padlen = 3 * (2 * len(sos) + 1)
    if x.shape[axis] <= padlen:
        raise LoperInputError(f"signal has {x.shape[axis]} samples; the filter needs more than {padlen}")
    from scipy.signal import sosfiltfilt

    return sosfiltfilt(sos, x, axis=axis)


def lowpass_gain(frequency_hz, sample_rate_hz: float, cutoff_hz: float = 40.0, order: int = 4) -> np.ndarray:
    """Magnitude response of :func:`lowpass` (the designed filter's gain squared) at ``frequency_hz``."""
    from scipy.signal import sosfreqz

    sos = _design(sample_rate_hz, cutoff_hz, order)
    _, h = sosfreqz(sos, worN=np.atleast_1d(np.asarray(frequency_hz, float)), fs=sample_rate_hz)
    return np.abs(h) ** 2
