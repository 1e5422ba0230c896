"""The zero-phase low-pass on sinusoids with known answers."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import CUTOFF_HZ, ORDER, check_cutoff, lowpass, lowpass_finite_runs

FS = 128.0


def lowpass_gain(frequency_hz, sample_rate_hz: float, cutoff_hz: float = CUTOFF_HZ, order: int = ORDER) -> np.ndarray:
    """Magnitude response of :func:`lowpass` (the designed filter's gain squared) at ``frequency_hz``."""
    from scipy.signal import sosfreqz

    sos = check_cutoff(sample_rate_hz, cutoff_hz, order)
    _, h = sosfreqz(sos, worN=np.atleast_1d(np.asarray(frequency_hz, float)), fs=sample_rate_hz)
    return np.abs(h) ** 2


def min_run_samples(sample_rate_hz: float, cutoff_hz: float, order: int) -> int:
    """Fewest samples :func:`lowpass` accepts: one more than the padding of ``sosfiltfilt`` (3 * (2 * sections + 1))."""
    return 3 * (2 * len(check_cutoff(sample_rate_hz, cutoff_hz, order)) + 1) + 1


@pytest.mark.parametrize("freq", [2.0, 10.0, 40.0, 50.0])
def test_sinusoid_gain_matches_the_squared_butterworth_response(freq):
    t = np.arange(0, 40, 1 / FS)
    x = np.sin(2 * np.pi * freq * t)
    y = lowpass(x, FS, 40.0, 4)
    mid = slice(len(t) // 4, 3 * len(t) // 4)  # away from the edges
    gain = np.sqrt(2 * np.mean(y[mid] ** 2))
    np.testing.assert_allclose(gain, lowpass_gain(freq, FS, 40.0, 4)[0], rtol=2e-3, atol=1e-4)


def test_gain_at_cutoff_is_minus_6_db_and_passband_is_flat():
    np.testing.assert_allclose(lowpass_gain(40.0, FS), 0.5, rtol=1e-9)
    assert abs(lowpass_gain(5.0, FS)[0] - 1) < 1e-6


def test_zero_phase_and_shapes():
    t = np.arange(0, 20, 1 / FS)
    x = np.sin(2 * np.pi * 3 * t)
    markers = np.stack([np.stack([x, 2 * x, 3 * x], -1)] * 4, axis=1)  # (frames, 4 markers, 3)
    y = lowpass(markers, FS)
    assert y.shape == markers.shape
    mid = slice(500, 2000)
    # no lag: the filtered sine lines up with the input (gain ~ 1 at 3 Hz)
    np.testing.assert_allclose(y[mid, 2, 1], markers[mid, 2, 1], atol=1e-6 * 2 + 2e-5)


def test_bad_input():
    x = np.zeros(500)
    x[123] = np.nan
    with pytest.raises(LoperInputError, match="sample 123"):
        lowpass(x, FS)
    with pytest.raises(LoperInputError, match="cutoff_hz must lie in 0 .. 64"):
        lowpass(np.zeros(500), FS, cutoff_hz=64.0)
    with pytest.raises(LoperInputError, match="needs more than"):
        lowpass(np.zeros(10), FS)


# ---------------------------------------------------------------- runs of finite samples


def _noisy_markers(n=1536, n_markers=3, seed=5):
    t = np.arange(n) / FS
    rng = np.random.default_rng(seed)
    base = 0.1 * np.sin(2 * np.pi * 1.1 * t) + 0.02 * np.sin(2 * np.pi * 7 * t)
    return np.stack([base[:, None] + 0.001 * rng.normal(size=(n, 3)) for _ in range(n_markers)], axis=1)


def test_runs_filter_equals_whole_signal_filter_away_from_the_gap():
    X = _noisy_markers()
    whole = lowpass(X, FS, 10.0, 4)
    gappy = X.copy()
    gappy[700:720, 1] = np.nan
    out, short = lowpass_finite_runs(gappy, FS, 10.0, 4)
    assert not short.any()
    assert np.isnan(out[700:720, 1]).all() and np.isnan(out).sum() == 20 * 3  # NaN stays NaN, nowhere else
    np.testing.assert_array_equal(out[:, [0, 2]], whole[:, [0, 2]])  # complete markers: exactly lowpass
    # one second (128 frames) off the gap's edges the run's own edge transient has died out
    far = np.r_[0 : 700 - 128, 720 + 128 : len(X)]
    diff = np.abs(out[far, 1] - whole[far, 1]).max()
    assert diff < 1e-11, diff  # measured 3.8e-13 m
    near = np.abs(out[690:700, 1] - whole[690:700, 1]).max()
    assert near > 1e-3  # measured 3.6 mm: beside the gap the run is filtered on its own: the comparison can fail


def test_short_runs_are_left_unfiltered_and_flagged():
    X = _noisy_markers(n=400, n_markers=1)
    shortest = min_run_samples(FS, 10.0, 4)
    assert shortest == 16  # sosfiltfilt pads 3 * (2 * 2 sections + 1) = 15 samples
    gappy = X.copy()
    gappy[100:110] = np.nan
    gappy[110 + shortest - 1 : 200] = np.nan  # a run of 15 samples between two gaps: too short
    gappy[200 + shortest : 210] = np.nan  # 16 samples: filtered
    out, short = lowpass_finite_runs(gappy, FS, 10.0, 4)
    np.testing.assert_array_equal(out[110 : 110 + shortest - 1], X[110 : 110 + shortest - 1])
    assert short[:, 0, 0].nonzero()[0].tolist() == list(range(110, 110 + shortest - 1))
    assert not np.array_equal(out[200 : 200 + shortest], X[200 : 200 + shortest])
    np.testing.assert_array_equal(np.isnan(out), np.isnan(gappy))


def test_runs_filter_refuses_infinite_samples_and_a_short_complete_signal():
    X = _noisy_markers(n=200, n_markers=1)
    X[30, 0, 1] = np.inf
    with pytest.raises(LoperInputError, match="infinite at sample 30"):
        lowpass_finite_runs(X, FS, 10.0)
    with pytest.raises(LoperInputError, match="signal has 10 samples; the filter needs more than 15"):
        lowpass_finite_runs(np.zeros(10), FS, 10.0)
