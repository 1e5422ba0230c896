"""The zero-phase low-pass on sinusoids with known answers."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.filtering import lowpass, lowpass_gain

FS = 128.0


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
