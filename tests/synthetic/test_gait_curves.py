"""Nominal gait curves: the Fourier defaults, the textbook landmarks and the stance-fraction warp."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.synthetic.gait_curves import (
    CURVE_KEYPOINTS_DEG,
    NominalGait,
    fourier_from_keypoints,
)

GAIT = NominalGait()


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
