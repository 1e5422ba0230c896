"""The averaging term: pairs about different swings, fitted from their mean with and without it."""

from dataclasses import replace

import numpy as np
import pytest

from loper_analysis.impedance.identification import identify_impedance
from loper_analysis.impedance.identification.pair_averaging import averaging_bias, averaging_corrected_fit, pair_windows
from loper_analysis.impedance.identification.validation import perturbed_trial
from loper_analysis.impedance.identification.window import prepare_window, window_options
from tests.impedance.identification.validation_windows import PARAMS, SETTINGS

#: Hip, knee, ankle K (N·m/rad) and D (N·m·s/rad) of the synthetic study's order at mid swing.
TRUTH = np.array([40.0, 2.0, 3.0, 0.05, 10.0, 0.5])
FIT = dict(n_starts=5, seed=0, lower=SETTINGS.lower, upper=SETTINGS.upper, tolerance=SETTINGS.tolerance)


def _pairs(swing_durations_s) -> dict:
    """Noise-free pairs of the same impedance, each about the nominal swing of its own duration (onset at 0)."""
    trials = [perturbed_trial(PARAMS, TRUTH, replace(SETTINGS, swing_duration_s=d)) for d in swing_durations_s]
    fp = np.stack([tr[3] for tr in trials])
    pelvis = np.stack([tr[4] for tr in trials])
    return {
        "time_s": trials[0][0] - SETTINGS.onset_s,
        "n_pairs": len(trials),
        "q_unperturbed": np.stack([tr[1] for tr in trials]),
        "q_perturbed": np.stack([tr[2] for tr in trials]),
        "pelvis_angle_unperturbed_rad": pelvis,
        "pelvis_angle_perturbed_rad": pelvis,
        "force_perturbed_n": fp,
        "force_unperturbed_n": np.zeros_like(fp),
        "force_time_s": trials[0][5] - SETTINGS.onset_s,
    }


def _mean_window(pairs: dict):
    m = {k: pairs[k].mean(axis=0) for k in pairs if k.startswith(("q_", "pelvis_", "force_")) and k != "force_time_s"}
    return prepare_window(
        pairs["time_s"],
        m["q_unperturbed"],
        m["q_perturbed"],
        PARAMS,
        0.0,
        force_unperturbed_n=m["force_unperturbed_n"],
        force_perturbed_n=m["force_perturbed_n"],
        force_time_s=pairs["force_time_s"],
        pelvis_angle_unperturbed_rad=m["pelvis_angle_unperturbed_rad"],
        pelvis_angle_perturbed_rad=m["pelvis_angle_perturbed_rad"],
        **window_options(SETTINGS),
    )


@pytest.fixture(scope="module")
def spread_pairs():
    return _pairs(np.linspace(0.45, 0.75, 7))


def test_the_mean_of_pairs_about_different_swings_is_fitted_with_a_bias_the_term_removes(spread_pairs):
    window = _mean_window(spread_pairs)
    plain = identify_impedance(window, **FIT)
    windows = pair_windows(spread_pairs, PARAMS, **window_options(SETTINGS))
    corrected_window, corrected, term = averaging_corrected_fit(window, windows, plain, **FIT)
    # the responses of noise-free pairs averaged: hip K off by > 1 N·m/rad, knee K by > 0.5 (the truth is 3)
    assert abs(plain.estimate[0] - TRUTH[0]) > 1.0
    assert abs(plain.estimate[2] - TRUTH[2]) > 0.5
    np.testing.assert_allclose(corrected.estimate[[0, 2]], TRUTH[[0, 2]], atol=0.01)
    np.testing.assert_allclose(corrected.estimate[[1, 3]], TRUTH[[1, 3]], atol=0.002)
    np.testing.assert_allclose(corrected_window.measured, window.measured - term, rtol=0, atol=0)
    assert 1e-3 < np.abs(term).max() < 0.05  # rad: small beside the response, not beside its error


def test_identical_pairs_have_no_averaging_term():
    pairs = _pairs([0.6] * 3)
    window = _mean_window(pairs)
    windows = pair_windows(pairs, PARAMS, **window_options(SETTINGS))
    assert len(windows) == 3
    assert np.abs(averaging_bias(window, windows, TRUTH)).max() < 1e-12
    fit = identify_impedance(window, **FIT)
    same_window, same, term = averaging_corrected_fit(window, [], fit, **FIT)
    assert same is fit and same_window is window and not term.any()
