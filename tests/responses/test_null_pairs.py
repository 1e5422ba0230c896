"""loper_analysis.responses.null_pairs: windows of unperturbed twin strides paired like perturbed ones
(tests.responses.twin_strides)."""

import numpy as np
import pytest

from loper_analysis.dynamics import joint_angles
from loper_analysis.resampling import window_times_s
from loper_analysis.responses import ResponseSettings, null_pair_windows
from tests.responses.twin_strides import DELAY, RATE, null_trial


@pytest.fixture
def rng():
    return np.random.default_rng(20240612)


def test_null_pair_windows_of_twins_are_identical_and_pool_trials(rng):
    """Twin pairs differ by nothing: zero differences in every coordinate; two trials pool their pairs."""
    a, _ = null_trial(rng)
    b, _ = null_trial(rng)
    b.name = "walk-m"
    settings = ResponseSettings(rate_hz=RATE)
    out = null_pair_windows([a.inputs(), b.inputs()], DELAY / RATE * 1e3, settings, source="S01")
    single = null_pair_windows([a.inputs()], DELAY / RATE * 1e3, settings)
    assert out["n_pairs"] == 2 * single["n_pairs"] >= 24 and out["n_outliers"] == 0
    np.testing.assert_allclose(out["time_s"], window_times_s(0.125, 0.25, RATE))
    assert out["q_perturbed"].shape == (out["n_pairs"], out["time_s"].size, 4)
    # joint angles and cart agree; the pelvis angle carries 1 mrad per stride number (make_trial)
    angles = [joint_angles(out[f"q_{w}"].reshape(-1, 4), out[f"pelvis_angle_{w}_rad"].reshape(-1))
              for w in ("perturbed", "unperturbed")]
    np.testing.assert_allclose(angles[0] - angles[1], 0.0, atol=1e-12)
    np.testing.assert_allclose(out["q_perturbed"][..., 0] - out["q_unperturbed"][..., 0], 0.0, atol=1e-12)
    dp = out["pelvis_angle_perturbed_rad"] - out["pelvis_angle_unperturbed_rad"]
    np.testing.assert_allclose(dp - dp[:, :1], 0.0, atol=1e-12)  # constant per pair:
    assert set(np.round(np.abs(dp[:, 0]) / 0.001).astype(int)) == {1, 2}  # twins are neighbours or (7, 9)
