"""loper_analysis.impedance.responses.windows: paired windows on one relative grid and the IQR rule on their
differences,
on swing-locked synthetic strides (tests.impedance.responses.twin_strides)."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.responses import match_unperturbed, paired_windows, window_outliers
from tests.impedance.responses.twin_strides import (
    BUMP_AMP,
    DELAY,
    JOINT_COLS,
    RATE,
    bump,
    twin_trial,
)

#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20240612


def test_paired_windows_grid_shapes_and_frame_values(rng):
    trial, _ = twin_trial(rng)
    t = trial.angles["time_s"].to_numpy()
    x = trial.angles[JOINT_COLS].to_numpy()
    force = trial.force["force_measured_n"].to_numpy()
    m = match_unperturbed(t, x, trial.strides)
    grid = window_times_s(0.025, 0.25, RATE)
    assert grid.size == 36 and grid[3] == 0.0
    for method in ("cubic", "linear"):
        w = paired_windows(t, {"joints": x, "force": force}, m, -0.025, 0.25, RATE, method=method)
        p, u = w["joints"]
        assert p.shape == u.shape == (4, 36, 3) and w["force"][0].shape == (4, 36)
        k = np.arange(-3, 33)
        kp = np.array([trial.onset[s] for s in m["stride"]])[:, None] + k
        ku = trial.toe_off[m["matched_stride"].to_numpy()][:, None] + DELAY + k
        np.testing.assert_allclose(p, x[kp], rtol=0, atol=1e-12)
        np.testing.assert_allclose(u, x[ku], rtol=0, atol=1e-12)
        np.testing.assert_allclose(w["force"][0] - w["force"][1], force[kp] - force[ku], atol=1e-12)


def test_paired_windows_nan_policy_and_errors(rng):
    trial, _ = twin_trial(rng)
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides)
    force = trial.force["force_measured_n"].to_numpy().copy()
    force[:20] = np.nan  # outside the robot log: allowed away from the windows
    w = paired_windows(t, {"force": force}, m, -0.125, 0.25, RATE)
    assert np.isfinite(w["force"][0]).all() and w["force"][0].shape == (4, 49)
    force[trial.onset[8] + 5] = np.nan
    with pytest.raises(LoperInputError, match=r"walk-1: column 'force': the perturbed window of stride 8"):
        paired_windows(t, {"force": force}, m, -0.125, 0.25, RATE, source="walk-1")
    with pytest.raises(LoperInputError, match="start_s <= 0 <= end_s"):
        paired_windows(t, {"force": force}, m, 0.01, 0.25, RATE)
    late = m.assign(onset_s=m["onset_s"] + 1e3)
    with pytest.raises(LoperInputError, match="leaves the finite data"):
        paired_windows(t, {"x": t}, late, -0.125, 0.25, RATE)


def test_window_outliers_judge_only_the_analysis_window(rng):
    grid = window_times_s(0.125, 0.25, RATE)
    shape = bump(grid)[None, :, None] * BUMP_AMP
    d = shape * rng.uniform(0.9, 1.1, (10, 1, 1)) + rng.normal(0.0, 1e-3, (10, grid.size, 3))
    d[2] -= 6.0 * shape[0]  # a bad pair: opposite response
    d[5, grid < -0.03] += 1.0  # bad only in the initial span, before the analysis window
    table = window_outliers(d, grid)
    assert table.attrs["judged"] and table.attrs["n_window_samples"] == 36
    assert table["pair"].tolist() == list(range(10))
    assert table["removed"].tolist() == [i == 2 for i in range(10)]
    assert "hip" in table.loc[2, "reason"] and table["judged"].all()
    # the whole grid would remove pair 5 as well: the restriction matters
    assert window_outliers(d, grid, before_s=0.125)["removed"].sum() == 2


def test_window_outliers_keep_few_pairs():
    grid = window_times_s(0.025, 0.25, RATE)
    table = window_outliers(np.zeros((3, grid.size, 3)), grid)
    assert not table.attrs["judged"] and not table["removed"].any() and not table["judged"].any()
    assert table["reason"].str.contains("needs >= 4").all()
    assert table["fraction_outlying_knee"].isna().all()
    assert window_outliers(np.zeros((0, grid.size, 3)), grid).empty
