"""The planner's inputs (planning.inputs): the planned pulse through the device loop (its step, its impulse, its
refused arguments), the pilot's trials picked by their perturbed strides' median onset, and a pilot trial cut into
stretches of the planned size."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from loper_analysis.device.analysis import step_metrics
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses import ResponseSettings
from loper_analysis.planning.inputs import pilot_onset_series, pilot_perturbed_pairs, pulse_force_n, trial_stretches
from loper_analysis.reference import STUDY_DEVICE
from loper_analysis.swing_leg.dynamics import segment_parameters_from_anthropometry
from loper_analysis.synthetic.coordinate_trials import perturbation_experiment

MATCHED = ResponseSettings(counterfactual="matched_stride")
HEIGHT_M, MASS_KG = 1.73, 64.9
ONSET_MS = 50
TRUTH = np.array([55.0, 3.5, 3.0, 0.10, 8.0, 0.3])


@pytest.fixture(scope="module")
def pilot():
    """A coordinate-level pilot: one trial with the device, perturbed near 50 ms after toe-off."""
    params = segment_parameters_from_anthropometry(HEIGHT_M, MASS_KG)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        full, _ = perturbation_experiment([11, 0], params, HEIGHT_M, ONSET_MS, TRUTH, [12], angle_noise_sd_rad=0.001)
    return full


def _median_onset_ms(trial) -> float:
    pert = trial["strides"][trial["strides"]["perturbed"].astype(bool)]
    return float(np.median(1e3 * (pert["onset_s"] - pert["toe_off_s"])))


def test_pulse_is_the_device_step():
    """A long pulse through the device loop with a still brace: settles at the desired force, rises in ~10 ms."""
    t = np.arange(-0.1, 0.6, 0.001)
    f = pulse_force_n(t, 40.0, 0.4)
    m = step_metrics(t, f, 40.0, (0.15, 0.3))
    np.testing.assert_allclose(m["steady_state_n"], 40.0, rtol=0.01)
    assert abs(m["rise_time_ms"] - STUDY_DEVICE["rise_time_ms"][0]) < 3.0  # study 10 ms; 12 ms after the 40 Hz low-pass
    assert 5.0 < m["overshoot_pct"] < STUDY_DEVICE["overshoot_pct"][0]  # the load cell's low-pass trims the overshoot
    assert np.max(np.abs(f[t < -0.02])) < 0.01 * 40.0  # the zero-phase low-pass rings ahead by < 1 %


@pytest.mark.parametrize("force_n, duration_s", [(40.0, 0.1), (-25.0, 0.05)])
def test_pulse_delivers_the_desired_impulse_and_dies_out(force_n, duration_s):
    """With a still brace the loop and the zero-phase low-pass pass a constant at unit gain, so the delivered
    impulse is the desired one, force_n * duration_s; 0.3 s after the pulse the force is gone."""
    t = np.arange(-0.1, 0.8, 0.001)
    f = pulse_force_n(t, force_n, duration_s)
    np.testing.assert_allclose(np.trapezoid(f, t), force_n * duration_s, rtol=1e-3)
    assert np.max(np.abs(f[t > duration_s + 0.3])) < 1e-3 * abs(force_n)
    assert np.sign(f[np.argmax(np.abs(f))]) == np.sign(force_n)


@pytest.mark.parametrize(
    "time_s, force_n, duration_s, message",
    [
        ([0.0], 40.0, 0.1, r"time_s must be a finite 1-D array with >= 2 samples, got shape \(1,\)"),
        ([0.0, np.nan], 40.0, 0.1, r"time_s must be a finite 1-D array with >= 2 samples, got shape \(2,\)"),
        ([0.0, 0.1], 40.0, 0.0, r"pulse duration_s must be > 0 s, got 0 s"),
        ([0.0, 0.1], 40.0, -0.05, r"pulse duration_s must be > 0 s, got -0.05 s"),
        ([0.0, 0.1], "forty", 0.1, r"pulse force_n must be a number, got 'forty'"),
    ],
)
def test_a_bad_pulse_is_refused_by_name(time_s, force_n, duration_s, message):
    with pytest.raises(LoperInputError, match=f"^{message}$"):
        pulse_force_n(np.asarray(time_s), force_n, duration_s)


def test_the_pilot_s_own_onset_gives_its_perturbed_pairs_with_a_zero_force(pilot):
    series = pilot_onset_series([pilot], ONSET_MS, MATCHED)
    pairs = pilot_perturbed_pairs([pilot], ONSET_MS, MATCHED)
    n = int(pairs["n_pairs"])
    assert 0 < n <= int(pilot["strides"]["perturbed"].sum())
    assert int(series["pairs"]["n_pairs"]) == n
    assert pairs["q_perturbed"].shape == (n, pairs["time_s"].size, 4)
    assert not np.any(series["force_perturbed_n"]) and not np.any(pairs["force_perturbed_n"])


def test_a_trial_is_the_onset_s_within_the_tolerance_of_its_median_onset(pilot):
    """The trial's perturbed strides' median onset m: onsets m +- 12 ms take it, m + 13 ms does not (default
    tolerance 12.5 ms); a wider tolerance takes it again."""
    m = _median_onset_ms(pilot)
    assert pilot_onset_series([pilot], m + 12.0, MATCHED) is not None
    assert pilot_onset_series([pilot], m - 12.0, MATCHED) is not None
    assert pilot_onset_series([pilot], m + 13.0, MATCHED) is None
    assert pilot_perturbed_pairs([pilot], m + 13.0, MATCHED) is None
    assert pilot_onset_series([pilot], m + 13.0, MATCHED, onset_tolerance_ms=14.0) is not None
    # the pairs take the series' options: the wider tolerance gives the same pairs as at the trial's own onset
    wider = pilot_perturbed_pairs([pilot], m + 13.0, MATCHED, onset_tolerance_ms=14.0, source="wider")
    own = pilot_perturbed_pairs([pilot], m, MATCHED)
    assert int(wider["n_pairs"]) == int(own["n_pairs"]) > 0
    np.testing.assert_array_equal(wider["q_perturbed"], own["q_perturbed"])
    with pytest.raises(TypeError, match="onset_tolerance"):
        pilot_perturbed_pairs([pilot], m, MATCHED, onset_tolerance=14.0)


def test_a_trial_without_onset_columns_is_passed_over(pilot):
    """A stride table without ``onset_s`` (a trial without the device) is nobody's onset: alone it gives None; next
    to the pilot it changes nothing."""
    bare = {"name": "nodevice", "angles": pilot["angles"], "strides": pilot["strides"].drop(columns="onset_s")}
    assert pilot_onset_series([bare], ONSET_MS, MATCHED) is None
    both = pilot_onset_series([bare, pilot], ONSET_MS, MATCHED)["pairs"]
    alone = pilot_onset_series([pilot], ONSET_MS, MATCHED)["pairs"]
    assert both["n_pairs"] == alone["n_pairs"]
    np.testing.assert_array_equal(both["q_perturbed"], alone["q_perturbed"])


def test_trial_stretches_hold_the_planned_perturbed_strides():
    """Strides of 1 s, perturbed 1, 3, 5, 7 and 9: stretches of 2 end before the heel strikes of strides 5 and 9;
    5 in one stretch is the whole trial; 6 none."""
    strides = pd.DataFrame(
        {
            "heel_strike_s": np.arange(12.0),
            "end_s": np.arange(12.0) + 1.0,
            "perturbed": np.isin(np.arange(12), [1, 3, 5, 7, 9]),
        }
    )
    trial = {"name": "T", "angles": pd.DataFrame({"time_s": np.arange(0, 1201) / 100.0}), "strides": strides}
    two = trial_stretches(trial, 2)
    assert [s["name"] for s in two] == ["T [1/2]", "T [2/2]"]
    assert two[0]["strides"]["heel_strike_s"].tolist() == [0, 1, 2, 3, 4]
    assert two[1]["strides"]["heel_strike_s"].tolist() == [5, 6, 7, 8]
    assert [int(s["strides"]["perturbed"].sum()) for s in two] == [2, 2]
    assert two[0]["angles"]["time_s"].iloc[[0, -1]].tolist() == [0.0, 5.0]
    assert two[1]["angles"]["time_s"].iloc[[0, -1]].tolist() == [5.0, 9.0]
    (whole,) = trial_stretches(trial, 5)
    assert len(whole["strides"]) == 12 and len(whole["angles"]) == 1201
    assert trial_stretches(trial, 6) == []
    with pytest.raises(LoperInputError, match="n_perturbed must be >= 1"):
        trial_stretches(trial, 0)


def test_trial_stretches_keep_the_perturbed_side_s_strides_in_order():
    """Both sides' strides, shuffled: only the right side's (perturbed 0 and 2 of 0, 1, 2, 3) are cut, sorted by
    heel strike; the refusal names the trial."""
    right = pd.DataFrame(
        {"side": "r", "heel_strike_s": [0.0, 1.0, 2.0, 3.0], "end_s": [1.0, 2.0, 3.0, 4.0], "perturbed": [1, 0, 1, 0]}
    )
    left = right.assign(side="l", heel_strike_s=right["heel_strike_s"] + 0.5, end_s=right["end_s"] + 0.5, perturbed=1)
    strides = pd.concat([right, left]).iloc[[5, 2, 0, 7, 3, 1, 4, 6]]
    trial = {"name": "walk03", "angles": pd.DataFrame({"time_s": np.arange(0, 451) / 100.0}), "strides": strides}
    first, second = trial_stretches(trial, 1, side="r")
    assert first["strides"]["heel_strike_s"].tolist() == [0.0, 1.0]
    assert second["strides"]["heel_strike_s"].tolist() == [2.0, 3.0]
    assert (first["strides"]["side"] == "r").all() and (second["strides"]["side"] == "r").all()
    assert second["angles"]["time_s"].iloc[[0, -1]].tolist() == [2.0, 4.0]
    assert [s["name"] for s in trial_stretches(trial, 1, side="l")] == [f"walk03 [{j}/4]" for j in (1, 2, 3, 4)]
    with pytest.raises(LoperInputError, match=r"^walk03: n_perturbed must be >= 1, got -1$"):
        trial_stretches(trial, -1)
