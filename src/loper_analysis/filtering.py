"""Zero-phase low-pass filtering of markers and forces (``docs/processing.md``, the filter)."""

from __future__ import annotations

import numpy as np

from loper_analysis.errors import LoperInputError

__all__ = ["DC_GAIN_TOLERANCE", "check_cutoff", "lowpass", "lowpass_finite_runs"]


#: Largest relative error of the designed filter's gain at 0 Hz: beyond it a cut-off is too low for the rate
#: (the poles crowd z = 1 and rounding takes over). Measured with scipy's butter at orders 2-8: the error is
#: below 2e-5 down to a cut-off of 1e-6 of Nyquist, 6e-5 .. 1e-3 at 1e-7 and 0.02 .. 0.1 at 1e-8, and at 1e-9
#: and below the design divides by zero (``LinAlgError: Singular matrix`` in sosfiltfilt). Order 1 stays sound.
DC_GAIN_TOLERANCE = 1e-3
#: Cut-off (Hz) of the markers' and forces' low-pass (config ``markers.filter.cutoff_hz``).
CUTOFF_HZ: float = 40.0
#: Designed Butterworth order, run forward and backward (config ``markers.filter.order``).
ORDER: int = 4


def _prefixed(source: str, message: str) -> str:
    return f"{source}: {message}" if source else message


def _padlen(sos: np.ndarray) -> int:
    """Samples ``sosfiltfilt`` pads each end with by default: 3 * (2 * sections + 1)."""
    return 3 * (2 * len(sos) + 1)


def check_cutoff(
    sample_rate_hz: float,
    cutoff_hz: float,
    order: int = 4,
    *,
    setting: str = "cutoff_hz",
    rate_name: str = "sample_rate_hz",
    source: str = "",
) -> np.ndarray:
    """Refuse a cut-off the zero-phase Butterworth low-pass cannot use at this rate; returns the filter (SOS).

    A cut-off must be a positive, finite frequency below the Nyquist
    frequency (half of ``sample_rate_hz``) and high enough that the designed
    filter is numerically sound: its sections finite and its gain at 0 Hz 1
    within :data:`DC_GAIN_TOLERANCE` (a cut-off of about 1e-7 of the Nyquist
    frequency and below fails this; 1e-9 Hz at 128 Hz made ``sosfiltfilt``
    raise ``LinAlgError: Singular matrix``).

    Parameters
    ----------
    sample_rate_hz : float
        Rate of the signal (Hz).
    cutoff_hz : float
        The cut-off (Hz).
    order : int
        Designed order (run forward and backward by :func:`lowpass`).
    setting : str
        Name of the cut-off in messages: the config key in full
        (``events.grf_cutoff_hz``) or the command-line option.
    rate_name : str
        Name of the rate in messages, e.g. the C3D parameter ``ANALOG:RATE``.
    source : str
        Prefix of messages: the file whose signal is filtered.

    Returns
    -------
    numpy.ndarray
        The filter's second-order sections (:func:`scipy.signal.butter`, ``output="sos"``).

    Raises
    ------
    LoperInputError
        A rate that is not positive and finite; an order that is not an
        integer >= 1; a cut-off that is not a number, not positive and finite,
        at or above Nyquist, or too low for the rate. The message names
        ``setting`` and its value, the rate and its Nyquist frequency.
    """
    import warnings

    from loper_analysis.timing import library_import

    with library_import():  # imported here: scipy.signal costs ~0.6 s, and most rules never filter
        from scipy.signal import butter, sosfilt_zi

    try:
        rate = float(sample_rate_hz)
    except (TypeError, ValueError):
        rate = float("nan")
    if not np.isfinite(rate) or rate <= 0:
        raise LoperInputError(_prefixed(source, f"{rate_name} must be a positive, finite rate, got {sample_rate_hz!r}"))
    if (
        isinstance(order, bool)
        or not isinstance(order, (int, float, np.integer, np.floating))
        or int(order) != order
        or order < 1
    ):
        raise LoperInputError(_prefixed(source, f"order must be an integer >= 1, got {order!r}"))
    nyq = 0.5 * rate
    rate_text = f"{rate_name} = {rate:g} Hz"
    try:
        value = float(cutoff_hz)
    except (TypeError, ValueError):
        raise LoperInputError(_prefixed(source, f"{setting} must be a frequency in Hz, got {cutoff_hz!r}")) from None
    if not np.isfinite(value) or value <= 0:
        raise LoperInputError(
            _prefixed(
                source,
                f"{setting} must be a positive, finite frequency below the Nyquist "
                f"frequency {nyq:g} Hz of {rate_text}, got {cutoff_hz!r}",
            )
        )
    if value >= nyq:
        raise LoperInputError(
            _prefixed(
                source,
                f"{setting} must lie in 0 .. {nyq:g} Hz (below the Nyquist frequency of {rate_text}), got {value:g} Hz",
            )
        )
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a singular design divides by zero: refused below, never a warning
        sos = butter(int(order), value / nyq, output="sos")
        dc_gain = float(np.prod(sos[:, :3].sum(axis=1) / sos[:, 3:].sum(axis=1)))
        sound = bool(np.all(np.isfinite(sos))) and abs(dc_gain - 1.0) <= DC_GAIN_TOLERANCE
        if sound:
            try:
                sound = bool(np.all(np.isfinite(sosfilt_zi(sos))))
            except np.linalg.LinAlgError:
                sound = False
    if not sound:
        raise LoperInputError(
            _prefixed(
                source,
                f"{setting} = {value:g} Hz is too low for {rate_text} (Nyquist {nyq:g} Hz): an order-{int(order)} "
                f"Butterworth at {value / nyq:.2g} of the Nyquist frequency is numerically unsound (its gain at 0 Hz "
                f"is {dc_gain:.6g}, not 1); raise {setting}",
            )
        )
    return sos


def lowpass(
    signal,
    sample_rate_hz: float,
    cutoff_hz: float = CUTOFF_HZ,
    order: int = ORDER,
    axis: int = 0,
    *,
    setting: str = "cutoff_hz",
    rate_name: str = "sample_rate_hz",
    source: str = "",
) -> np.ndarray:
    """Butterworth low-pass of ``order`` run forward and backward (zero phase).

    The forward-backward pass squares the magnitude response: the gain at
    ``cutoff_hz`` is 0.5 (-6 dB) and the roll-off that of order ``2 * order``
    (``tests/test_filtering.py`` checks both on sinusoids). ``signal`` is an array sampled along ``axis``
    (e.g. (n_frames, n_markers, 3) markers in m, or (n_samples,) forces in N);
    it must be finite (fill marker gaps first). Returns a new array of the same
    shape. ``setting``, ``rate_name`` and ``source`` name the cut-off, the rate
    and the file in messages (:func:`check_cutoff`).

    Raises
    ------
    LoperInputError
        Non-finite samples (the first is named), a cut-off refused by
        :func:`check_cutoff` (at or above Nyquist, too low, not positive), a
        signal too short for the filter's padding.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim == 0:
        raise LoperInputError(_prefixed(source, "signal must have at least one dimension"))
    bad = np.argwhere(~np.isfinite(x))
    if bad.size:
        idx = tuple(int(i) for i in bad[0])
        raise LoperInputError(
            _prefixed(source, f"signal is not finite at sample {idx[axis]} (index {idx}): fill gaps before filtering")
        )
    sos = check_cutoff(sample_rate_hz, cutoff_hz, order, setting=setting, rate_name=rate_name, source=source)
    padlen = _padlen(sos)
    if x.shape[axis] <= padlen:
        raise LoperInputError(
            _prefixed(source, f"signal has {x.shape[axis]} samples; the filter needs more than {padlen}")
        )
    from scipy.signal import sosfiltfilt

    return sosfiltfilt(sos, x, axis=axis)


def _finite_runs(finite: np.ndarray) -> list[tuple[int, int]]:
    """Runs of True in a 1-D bool array as (start, stop) index pairs, stop exclusive."""
    edges = np.diff(np.r_[0, finite.astype(np.int8), 0])
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def lowpass_finite_runs(
    signal,
    sample_rate_hz: float,
    cutoff_hz: float = CUTOFF_HZ,
    order: int = ORDER,
    axis: int = 0,
    *,
    setting: str = "cutoff_hz",
    rate_name: str = "sample_rate_hz",
    source: str = "",
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`lowpass` of each run of finite samples on its own; NaN stays NaN and never spreads.

    Every 1-D series along ``axis`` (e.g. one coordinate of one marker of
    (n_frames, n_markers, 3) markers in m) is cut at its NaN samples and each
    finite run is filtered forward and backward as a signal of its own, with
    ``sosfiltfilt``'s padding at both of its ends. A run no longer than that
    padding (3 * (2 * sections + 1) samples, 15 for order 4) is too short for it and is left
    as it is (unfiltered, reported in the returned mask): dropping it would
    lose real samples, while the filter's edge transients would dominate it
    anyway. A signal without NaN gives exactly :func:`lowpass`'s result (and
    is refused like there when it is too short). ``setting``, ``rate_name``
    and ``source`` name the cut-off, the rate and the file in messages
    (:func:`check_cutoff`).

    Returns
    -------
    filtered : numpy.ndarray
        Same shape as ``signal``; NaN where ``signal`` is NaN.
    unfiltered : numpy.ndarray of bool
        Same shape: True for finite samples of runs too short to filter.

    Raises
    ------
    LoperInputError
        Infinite samples (the first is named), a cut-off refused by
        :func:`check_cutoff`, a bad order, a signal without NaN too short for
        the filter.
    """
    x = np.asarray(signal, dtype=float)
    if x.ndim == 0:
        raise LoperInputError(_prefixed(source, "signal must have at least one dimension"))
    if np.any(np.isinf(x)):
        idx = tuple(int(i) for i in np.argwhere(np.isinf(x))[0])
        raise LoperInputError(_prefixed(source, f"signal is infinite at sample {idx[axis]} (index {idx})"))
    sos = check_cutoff(sample_rate_hz, cutoff_hz, order, setting=setting, rate_name=rate_name, source=source)
    if np.all(np.isfinite(x)):  # the whole signal is one run (too short a one is refused, as by lowpass)
        return (
            lowpass(x, sample_rate_hz, cutoff_hz, order, axis, setting=setting, rate_name=rate_name, source=source),
            np.zeros(x.shape, dtype=bool),
        )
    from scipy.signal import sosfiltfilt

    shortest = _padlen(sos) + 1
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
