"""The response's rod force at the robot rate (loper_analysis.impedance.responses.native_force) against a known
force."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses import ResponseSettings, subject_onset_response
from loper_analysis.impedance.responses.native_force import finite_spans
from tests.impedance.responses.twin_strides import twin_trial

ROBOT_HZ = 1000.0
ANGLE = np.deg2rad(-20.0)  # a fixed rod direction: the known answer needs no interpolation of it

#: The study's matching, whose matched strides these tests check.
MATCHED = ResponseSettings(min_strides=4, counterfactual="matched_stride")


def linear_force(t):
    """Force (N) linear in time: its straight-line interpolation between robot samples is exact."""
    return 3.0 + 7.0 * t


def native_inputs(rng, start_s=None, end_s=None):
    trial, _ = twin_trial(rng)
    t = trial.angles["time_s"].to_numpy()
    lo = t[0] if start_s is None else start_s
    hi = t[-1] if end_s is None else end_s
    tn = lo + 0.0003 + np.arange(int((hi - lo) * ROBOT_HZ)) / ROBOT_HZ  # robot samples between the frames
    native = pd.DataFrame({"time_s": tn, "force_measured_n": linear_force(tn)})
    inputs = trial.inputs()
    inputs["force_direction"] = np.tile([np.cos(ANGLE), np.sin(ANGLE)], (t.size, 1))
    inputs["force_native"] = native
    return trial, inputs


def test_response_force_at_the_robot_rate_is_the_mean_of_the_pairs():
    """1 kHz grid from -125 to 250 ms; the mean over pairs of F(anchor + grid) x direction, with F linear:
    F(mean anchor + grid) x direction, to rounding."""
    rng = np.random.default_rng(20240612)
    trial, inputs = native_inputs(rng)
    _, counts, series = subject_onset_response([inputs], 100, MATCHED)
    grid = window_times_s(0.125, 0.25, ROBOT_HZ)
    np.testing.assert_allclose(series["force_time_s"], grid, rtol=0, atol=1e-15)
    assert series["force_perturbed_n"].shape == (grid.size, 2) == series["force_unperturbed_n"].shape
    pairs = counts.attrs["pairs"]
    kept = pairs[~pairs["removed"]]
    u = np.array([np.cos(ANGLE), np.sin(ANGLE)])
    for what, col in (("perturbed", "onset_s"), ("unperturbed", "matched_anchor_s")):
        expected = linear_force(kept[col].mean() + grid)[:, None] * u
        np.testing.assert_allclose(series[f"force_{what}_n"], expected, rtol=0, atol=1e-9)


def test_force_at_the_robot_rate_must_cover_every_window():
    """A robot log that starts at the first perturbed onset: that stride's window (from 125 ms before) is refused."""
    trial, _ = twin_trial(np.random.default_rng(20240612))
    first = min(trial.onset)
    onset_s = float(trial.angles["time_s"].iloc[trial.onset[first]])
    _, inputs = native_inputs(np.random.default_rng(20240612), start_s=onset_s)
    with pytest.raises(LoperInputError, match=rf"perturbed force window of stride {first} .* leaves the finite force"):
        subject_onset_response([inputs], 100, MATCHED)


def test_force_at_the_robot_rate_for_every_trial_or_none():
    rng = np.random.default_rng(20240612)
    _, with_native = native_inputs(rng)
    other, _ = twin_trial(rng, name="walk-2")
    with pytest.raises(
        LoperInputError, match="walk-2: the force at the robot rate .* every trial of the onset or for none"
    ):
        subject_onset_response([with_native, other.inputs()], 100, MATCHED)


def test_finite_spans_equals_a_mask_per_span():
    rng = np.random.default_rng(3)
    t = np.sort(rng.uniform(0.0, 10.0, 2000))
    v = rng.normal(size=t.size)
    v[rng.choice(t.size, 25, replace=False)] = np.nan
    lo = rng.uniform(-1.0, 10.0, 500)
    hi = lo + rng.uniform(0.0, 0.5, 500)
    lo[:3], hi[:3] = t[:3], t[:3]  # ends on samples: included
    expected = [bool(np.all(np.isfinite(v[(t >= a) & (t <= b)]))) for a, b in zip(lo, hi)]
    got = finite_spans(t, v, lo, hi)
    assert got.tolist() == expected
    assert 0 < int(got.sum()) < got.size
