"""Zero-phase low-pass filtering of markers and forces (``docs/processing.md``, the filter)."""

from __future__ import annotations

import numpy as np

from .errors import LoperInputError

__all__ = ["lowpass", "lowpass_finite_runs", "lowpass_gain", "min_run_samples"]


def _design(sample_rate_hz: float, cutoff_hz: float, order: int):
    from .io.timing import library_import

    with library_import():  # imported here: scipy.signal costs ~0.6 s, and most rules never filter
        from scipy.signal import butter

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


def min_run_samples(sample_rate_hz: float, cutoff_hz: float = 40.0, order: int = 4) -> int:
    """Fewest samples :func:`lowpass` accepts: one more than the padding of ``sosfiltfilt`` (3 * (2 * sections + 1))."""
    sos = _design(sample_rate_hz, cutoff_hz, order)
    return 3 * (2 * len(sos) + 1) + 1


def _finite_runs(finite: np.ndarray) -> list[tuple[int, int]]:
    """Runs of True in a 1-D bool array as (start, stop) index pairs, stop exclusive."""
    edges = np.diff(np.r_[0, finite.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def lowpass_finite_runs(signal, sample_rate_hz: float, cutoff_hz: float = 40.0, order: int = 4,
                        axis: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`lowpass` of each run of finite samples on its own; NaN stays NaN and never spreads.

    Every 1-D series along ``axis`` (e.g. one coordinate of one marker of
    (n_frames, n_markers, 3) markers in m) is cut at its NaN samples and each
    finite run is filtered forward and backward as a signal of its own, with
    ``sosfiltfilt``'s padding at both of its ends. A run of fewer than
    :func:`min_run_samples` samples is too short for that padding and is left
    as it is (unfiltered, reported in the returned mask): dropping it would
    lose real samples, while the filter's edge transients would dominate it
    anyway. A signal without NaN gives exactly :func:`lowpass`'s result (and
    is refused like there when it is too short).

    Returns
    -------
    filtered : numpy.ndarray
        Same shape as ``signal``; NaN where ``signal`` is NaN.
    unfiltered : numpy.ndarray of bool
        Same shape: True for finite samples of runs too short to filter.

    Raises
    ------
    LoperInputError
        Infinite samples (the first is named), a cut-off at or above Nyquist,
        a bad order, a signal without NaN too short for the filter.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim == 0:
        raise LoperInputError("signal must have at least one dimension")
    if np.any(np.isinf(x)):
        idx = tuple(int(i) for i in np.argwhere(np.isinf(x))[0])
        raise LoperInputError(f"signal is infinite at sample {idx[axis]} (index {idx})")
    sos = _design(sample_rate_hz, cutoff_hz, order)
    if np.all(np.isfinite(x)):  # the whole signal is one run (too short a one is refused, as by lowpass)
        return lowpass(x, sample_rate_hz, cutoff_hz, order, axis), np.zeros(x.shape, dtype=bool)
    from scipy.signal import sosfiltfilt

    shortest = 3 * (2 * len(sos) + 1) + 1
    moved = np.moveaxis(x, axis, 0)
    flat = moved.reshape(moved.shape[0], -1)
    out = flat.copy()
    short = np.zeros(flat.shape, dtype=bool)
    finite = np.isfinite(flat)
    groups: dict[bytes, list[int]] = {}  # columns with the same finite samples are filtered together
    for j in range(flat.shape[1]):
        groups.setdefault(np.packbits(finite[:, j]).tobytes(), []).append(j)
    for cols in groups.values():
        for start, stop in _finite_runs(finite[:, cols[0]]):
            if stop - start < shortest:
                short[start:stop, cols] = True
            else:
                out[start:stop, cols] = sosfiltfilt(sos, flat[start:stop, cols], axis=0)
    return np.moveaxis(out.reshape(moved.shape), 0, axis), np.moveaxis(short.reshape(moved.shape), 0, axis)


def lowpass_gain(frequency_hz, sample_rate_hz: float, cutoff_hz: float = 40.0, order: int = 4) -> np.ndarray:
    """Magnitude response of :func:`lowpass` (the designed filter's gain squared) at ``frequency_hz``."""
    from scipy.signal import sosfreqz

    sos = _design(sample_rate_hz, cutoff_hz, order)
    _, h = sosfreqz(sos, worN=np.atleast_1d(np.asarray(frequency_hz, float)), fs=sample_rate_hz)
    return np.abs(h) ** 2
