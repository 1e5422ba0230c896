"""loper_analysis.impedance.responses.null_pairs: windows of unperturbed twin strides paired like perturbed ones
(tests.impedance.responses.twin_strides), and the screen that leaves out a trial whose null pairs deviate far more."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses import (
    ResponseSettings,
    deviant_trials,
    null_pair_windows,
    trial_deviation_rad,
)
from loper_analysis.swing_leg.dynamics import joint_angles
from tests.impedance.responses.twin_strides import DELAY, RATE, null_trial, twin_trial

#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20240612


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
    angles = [
        joint_angles(out[f"q_{w}"].reshape(-1, 4), out[f"pelvis_angle_{w}_rad"].reshape(-1))
        for w in ("perturbed", "unperturbed")
    ]
    np.testing.assert_allclose(angles[0] - angles[1], 0.0, atol=1e-12)
    np.testing.assert_allclose(out["q_perturbed"][..., 0] - out["q_unperturbed"][..., 0], 0.0, atol=1e-12)
    dp = out["pelvis_angle_perturbed_rad"] - out["pelvis_angle_unperturbed_rad"]
    np.testing.assert_allclose(dp - dp[:, :1], 0.0, atol=1e-12)  # constant per pair:
    assert set(np.round(np.abs(dp[:, 0]) / 0.001).astype(int)) == {1, 2}  # twins are neighbours or (7, 9)


def test_trial_deviation_is_the_median_rms_over_the_analysis_window():
    grid = window_times_s(0.125, 0.25, RATE)
    inside = (grid >= -0.025 - 1e-9) & (grid <= 0.25 + 1e-9)
    d = np.zeros((3, grid.size, 3))
    d[0, inside] = 0.01  # RMS 0.01
    d[1, inside] = [0.02, 0.0, 0.0]  # RMS 0.02 / sqrt(3)
    d[2, inside] = 0.05
    d[:, ~inside] = 9.0  # outside the analysis window: ignored
    assert trial_deviation_rad(d, grid, 0.025, 0.25) == pytest.approx(0.02 / np.sqrt(3), rel=1e-12)
    assert np.isnan(trial_deviation_rad(d[:0], grid, 0.025, 0.25))


def test_deviant_trials_against_the_median_of_the_others():
    dev = {"a": 0.010, "b": 0.012, "c": 0.011, "bad": 0.04, "empty": float("nan")}
    out = deviant_trials(dev)  # 0.04 > 3 x median(0.010, 0.012, 0.011) = 0.033
    assert list(out) == ["bad"]
    assert out["bad"] == (
        "trial bad left out of the null pairs: its null pairs deviate by 0.04 rad (median RMS), "
        "3.64 times the other trials' 0.011 rad (limit 3 times)"
    )
    assert deviant_trials(dev, max_ratio=4.0) == {} and deviant_trials(dev, max_ratio=None) == {}
    assert list(deviant_trials({"good": 0.01, "bad": 0.05})) == ["bad"]  # two trials: only the larger can go
    assert deviant_trials({"only": 1.0}) == {}
    with pytest.raises(LoperInputError, match="max_ratio must be a finite number >= 1.0, got 0.5"):
        deviant_trials(dev, max_ratio=0.5)


def test_a_deviant_trial_leaves_the_pool_as_if_it_were_absent(rng):
    """A copy of a trial with every joint angle 20x: its null pairs deviate exactly 20x as much (the matches
    are the same); it is left out and the pool equals the pool without it."""
    a, _ = twin_trial(np.random.default_rng(7), "walk-a")
    b, _ = twin_trial(rng, "walk-b")
    bad, _ = twin_trial(np.random.default_rng(7), "walk-bad")
    cols = [c for c in bad.angles.columns if c.endswith("_left_rad")]
    bad.angles[cols] = 20.0 * bad.angles[cols]
    settings = ResponseSettings(rate_hz=RATE)
    onset = DELAY / RATE * 1e3
    screened = null_pair_windows([a.inputs(), bad.inputs(), b.inputs()], onset, settings)
    pooled = null_pair_windows([a.inputs(), b.inputs()], onset, settings)
    assert list(screened["trials_left_out"]) == ["walk-bad"] and pooled["trials_left_out"] == {}
    assert screened["n_pairs"] == pooled["n_pairs"]
    for key in ("q_perturbed", "q_unperturbed", "pelvis_angle_perturbed_rad"):
        np.testing.assert_array_equal(screened[key], pooled[key])
    dev = screened["trial_deviation_rad"]
    assert dev["walk-bad"] == pytest.approx(20.0 * dev["walk-a"], rel=1e-9)
    assert 0.005 < dev["walk-a"] < 0.05 and 0.005 < dev["walk-b"] < 0.05
    unscreened = null_pair_windows([a.inputs(), bad.inputs(), b.inputs()], onset, settings, max_trial_ratio=None)
    assert unscreened["trials_left_out"] == {} and unscreened["n_pairs"] + unscreened["n_outliers"] > pooled["n_pairs"]
