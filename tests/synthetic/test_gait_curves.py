"""Nominal gait curves: the Fourier defaults, the textbook landmarks and the stance-fraction warp."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.gait_curves import FourierSeries, NominalGait

GAIT = NominalGait()

#: Key points the default joint-angle curves were fitted to: (stride fraction, degrees); heel strike at 0, toe-off at
#: 0.65 (read off the textbook curves' general shape, not digitised).
CURVE_KEYPOINTS_DEG: dict[str, tuple[tuple[float, float], ...]] = {
    "hip_flexion": (
        (0.00, 25.0),
        (0.10, 24.0),
        (0.30, 10.0),
        (0.50, -5.0),
        (0.58, -10.0),
        (0.65, -3.0),
        (0.73, 15.0),
        (0.83, 27.0),
        (0.92, 26.5),
    ),
    "knee_flexion": (
        (0.00, 5.0),
        (0.06, 10.0),
        (0.15, 15.0),
        (0.26, 10.0),
        (0.40, 5.0),
        (0.48, 7.0),
        (0.56, 16.0),
        (0.65, 38.0),
        (0.71, 55.0),
        (0.76, 60.0),
        (0.80, 57.0),
        (0.86, 35.0),
        (0.92, 14.0),
        (0.97, 6.0),
    ),
    "ankle_dorsiflexion": (
        (0.00, 0.0),
        (0.07, -5.0),
        (0.16, -1.0),
        (0.30, 5.0),
        (0.47, 10.0),
        (0.55, 7.0),
        (0.61, -3.0),
        (0.68, -12.0),
        (0.73, -6.0),
        (0.79, 1.0),
        (0.87, 3.0),
        (0.94, 1.0),
    ),
}


def fourier_from_keypoints(phase, values, n_harmonics: int = 8, n_samples: int = 1000) -> FourierSeries:
    """The first ``n_harmonics`` harmonics of the periodic cubic spline through the key points (``phase`` in [0, 1)
    from 0, strictly increasing; the curve closes at 1 with its value at 0)."""
    spline = CubicSpline(np.append(phase, 1.0), np.append(values, values[0]), bc_type="periodic")
    F = np.fft.rfft(spline(np.arange(n_samples) / n_samples)) / n_samples
    return FourierSeries(F[0].real, 2.0 * F[1 : n_harmonics + 1].real, -2.0 * F[1 : n_harmonics + 1].imag)


def test_default_coefficients_are_the_fit_of_the_documented_keypoints():
    for joint, kp in CURVE_KEYPOINTS_DEG.items():
        phase, deg = np.array(kp).T
        fit = fourier_from_keypoints(phase, np.deg2rad(deg))
        series = GAIT.joint_series(joint)
        # defaults are printed with 6 decimals (rad)
        np.testing.assert_allclose(series.cos, fit.cos, atol=6e-7)
        np.testing.assert_allclose(series.sin, fit.sin, atol=6e-7)
        np.testing.assert_allclose(series.mean, fit.mean, atol=6e-7)
        # and pass through the key points within 0.4 deg (8 harmonics)
        np.testing.assert_allclose(np.rad2deg(series(phase)), deg, atol=0.4)


def test_nominal_curve_landmarks():
    phase = np.linspace(0.0, 1.0, 2001)
    a = {k: np.rad2deg(v) for k, v in GAIT.joint_angles(phase).items()}
    hip, knee, ankle = a["hip_flexion"], a["knee_flexion"], a["ankle_dorsiflexion"]
    assert abs(hip[0] - 25) < 0.5 and abs(hip.min() + 10) < 0.5 and 0.5 < phase[hip.argmin()] < 0.65
    assert abs(knee[0] - 5) < 0.5 and abs(knee.max() - 60) < 0.5 and 0.7 < phase[knee.argmax()] < 0.85
    loading = (phase > 0.05) & (phase < 0.3)
    assert abs(knee[loading].max() - 15) < 0.5
    assert abs(ankle[0]) < 0.5 and abs(ankle.max() - 10) < 0.5 and abs(ankle.min() + 12) < 0.5
    assert 0.65 < phase[ankle.argmin()] < 0.72  # plantarflexion peak just after toe-off


def test_stance_fraction_warp_moves_toe_off_of_the_curves():
    """The monotone C1 warp puts the curves' toe-off (0.65) at the new stance fraction (0.6)."""
    g = NominalGait(stance_fraction=0.6)
    phase = np.linspace(0.0, 1.0, 4001)
    psi = g.curve_phase(phase[:-1])
    assert np.all(np.diff(psi) > 0)
    np.testing.assert_allclose(g.curve_phase([0.0, 0.6]), [0.0, 0.65], atol=1e-12)
    knee = g.joint_angles([0.6])["knee_flexion"]
    np.testing.assert_allclose(knee, GAIT.knee_flexion_rad([0.65]), atol=1e-12)
    # slope continuous across toe-off and across the stride boundary (C1 warp)
    d = np.diff(np.concatenate([psi, [1.0]])) * 4000
    assert np.max(np.abs(np.diff(d))) < 0.01


def test_stance_fraction_outside_walking_is_refused():
    with pytest.raises(LoperInputError, match="stance_fraction"):
        NominalGait(stance_fraction=0.4)
