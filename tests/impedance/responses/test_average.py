"""loper_analysis.impedance.responses.average: the mean response of a subject and onset returns the planted bumps,
counts every dropped stride and checks its trial frames (tests.impedance.responses.twin_strides)."""

import numpy as np
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.resampling import window_times_s
from loper_analysis.impedance.identification import prepare_window
from loper_analysis.impedance.responses import (
    COUNT_COLUMNS,
    ResponseSettings,
    subject_onset_response,
)
from loper_analysis.impedance.responses.response_window import ResponseWindow
from loper_analysis.swing_leg.dynamics import (
    segment_coordinates,
    segment_parameters_from_anthropometry,
)
from tests.impedance.responses.twin_strides import (
    BUMP_AMP,
    DELAY,
    JOINT_COLS,
    PULSE_N,
    RATE,
    bump,
    make_trial,
    twin_trial,
)

#: The study's matching, whose matched strides these tests check.
MATCHED = ResponseSettings(min_strides=4, counterfactual="matched_stride")


#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20240612


def test_subject_response_returns_the_planted_bump(rng):
    amplitudes = {4: 1.0, 8: 1.1, 12: 1.3, 16: 0.8}
    trial, _ = twin_trial(rng, amplitudes={p: BUMP_AMP * a for p, a in amplitudes.items()})
    response, counts, series = subject_onset_response([trial.inputs()], 100, MATCHED)
    grid = window_times_s(0.125, 0.25, RATE)
    np.testing.assert_array_equal(response["time_s"], grid)
    a = np.array(list(amplitudes.values()))
    shape = bump(grid)
    for j, joint in enumerate(JOINTS):
        np.testing.assert_allclose(response[f"{joint}_rad_mean"], a.mean() * BUMP_AMP[j] * shape, rtol=0, atol=1e-9)
        np.testing.assert_allclose(response[f"{joint}_rad_sd"], a.std(ddof=1) * BUMP_AMP[j] * shape, atol=1e-9)
    pulse = PULSE_N * ((grid >= -1e-12) & (grid < 13 / RATE - 1e-12))
    np.testing.assert_allclose(response["force_n_mean"], pulse, atol=1e-9)
    np.testing.assert_allclose(response["force_n_sd"], 0.0, atol=1e-9)
    assert (response["n_pairs"] == 4).all() and response["analysis_window"].sum() == 36

    # frame-index expectations for the means and the identification series
    x = trial.angles[JOINT_COLS].to_numpy()
    pel = trial.angles["pelvis_angle_rad"].to_numpy()
    px = trial.angles["pelvis_x_m"].to_numpy()
    fvec = trial.force["force_measured_n"].to_numpy()[:, None] * trial.direction
    k = np.arange(-16, 33)
    kp = np.array([trial.onset[s] for s in (4, 8, 12, 16)])[:, None] + k
    ku = trial.toe_off[[1, 6, 10, 14]][:, None] + DELAY + k
    for j, joint in enumerate(JOINTS):
        np.testing.assert_allclose(response[f"{joint}_perturbed_rad_mean"], x[kp, j].mean(0), atol=1e-12)
        np.testing.assert_allclose(response[f"{joint}_unperturbed_rad_mean"], x[ku, j].mean(0), atol=1e-12)
    for what, kk in (("perturbed", kp), ("unperturbed", ku)):
        q = segment_coordinates(x[kk].reshape(-1, 3), pel[kk].ravel(), px[kk].ravel()).reshape(4, k.size, 4)
        np.testing.assert_allclose(series[f"q_{what}"], q.mean(0), atol=1e-12)
        np.testing.assert_allclose(series[f"pelvis_angle_{what}_rad"], pel[kk].mean(0), atol=1e-12)
        np.testing.assert_allclose(series[f"force_{what}_n"], fvec[kk].mean(0), atol=1e-12)
    assert series["force_perturbed_n"].shape == (k.size, 2) and series["n_pairs"] == 4
    assert series["onset_s"] == 0.0
    np.testing.assert_array_equal(series["time_s"], grid)

    # the series is what prepare_window takes; its measured difference is the mean response
    window = prepare_window(
        series["time_s"],
        series["q_unperturbed"],
        series["q_perturbed"],
        segment_parameters_from_anthropometry(1.75, 70.0),
        series["onset_s"],
        force_unperturbed_n=series["force_unperturbed_n"],
        force_perturbed_n=series["force_perturbed_n"],
        pelvis_angle_unperturbed_rad=series["pelvis_angle_unperturbed_rad"],
        pelvis_angle_perturbed_rad=series["pelvis_angle_perturbed_rad"],
        window=ResponseWindow(series["window_before_s"], series["window_after_s"], series["initial_state_span_s"]),
    )
    inside = response[response["analysis_window"]]
    np.testing.assert_allclose(window.time_s, inside["time_s"], atol=1e-12)
    np.testing.assert_allclose(window.measured, inside[[f"{j}_rad_mean" for j in JOINTS]].to_numpy(), atol=1e-9)
    assert counts["status"].tolist() == ["ok", "ok"]


def test_subject_counts_too_short_no_match_outlier(rng):
    good = {4: 1.0, 8: 1.1, 12: 1.2, 16: 1.3}
    amplitudes = {p: BUMP_AMP * a for p, a in good.items()}
    amplitudes[20] = -5.0 * BUMP_AMP  # an outlier, with its twin 18
    amplitudes[22] = BUMP_AMP  # its swing is made too short below
    trial_a, _ = twin_trial(
        rng, "walk-1", twins={4: 1, 8: 6, 12: 10, 16: 14, 20: 18}, amplitudes=amplitudes, short=(22,)
    )
    j = np.arange(8)
    trial_b = make_trial(
        "walk-2",
        88 + j % 3,
        60 + j % 2,
        rng.uniform(-0.05, 0.05, (8, 3)),
        {3: BUMP_AMP, 6: BUMP_AMP},
        removed=[s for s in range(8) if s not in (3, 6)],
    )
    with pytest.warns(TooFewStridesWarning, match="only 4 valid"):
        response, counts, _ = subject_onset_response([trial_a.inputs(), trial_b.inputs()], 100, source="S01")
    assert list(counts.columns) == list(COUNT_COLUMNS)
    assert counts["trial"].tolist() == ["walk-1", "walk-2", "total"]
    assert counts["n_perturbed"].tolist() == [6, 2, 8]
    assert counts["n_too_short"].tolist() == [1, 0, 1]
    assert counts["n_no_match"].tolist() == [0, 2, 2]
    assert counts["n_outliers"].tolist() == [1, 0, 1]
    assert counts["n_kept"].tolist() == [4, 0, 4]
    assert counts["status"].tolist() == ["too_few_strides"] * 3
    assert "1 too short" in counts["reason"].iloc[0] and "2 without unperturbed match" in counts["reason"].iloc[1]
    pairs = counts.attrs["pairs"]
    assert pairs["stride"].tolist() == [4, 8, 12, 16, 20] and pairs["removed"].tolist() == [0, 0, 0, 0, 1]
    np.testing.assert_allclose(
        response["hip_rad_mean"],
        np.mean(list(good.values())) * BUMP_AMP[0] * bump(response["time_s"].to_numpy()),
        atol=1e-9,
    )
    _, counts, _ = subject_onset_response([trial_a.inputs(), trial_b.inputs()], 100, MATCHED)
    assert counts["status"].tolist() == ["ok", "too_few_strides", "ok"]


def test_subject_response_with_no_pair_is_nan_not_a_crash(rng):
    j = np.arange(8)
    trial = make_trial(
        "walk-2",
        88 + j % 3,
        60 + j % 2,
        rng.uniform(-0.05, 0.05, (8, 3)),
        {3: BUMP_AMP},
        removed=[s for s in range(8) if s != 3],
    )
    with pytest.warns(TooFewStridesWarning):
        response, counts, series = subject_onset_response([trial.inputs()], 100)
    assert response["hip_rad_mean"].isna().all() and (response["n_pairs"] == 0).all()
    assert np.isnan(series["q_perturbed"]).all() and series["q_perturbed"].shape == (49, 4)
    assert counts.loc[0, "n_no_match"] == 1 and "not judged" in counts["reason"].iloc[-1]


def test_subject_inputs_are_checked(rng):
    trial, _ = twin_trial(rng)
    bad = trial.inputs() | {"force_direction": trial.direction * 2.0}
    with pytest.raises(LoperInputError, match="walk-1: force_direction at frame 0 .* not a unit vector"):
        subject_onset_response([bad], 100)
    bad = trial.inputs() | {"angles": trial.angles.drop(columns="knee_left_rad")}
    with pytest.raises(LoperInputError, match=r"walk-1 \(angles\): column\(s\) \['knee_left_rad'\] missing"):
        subject_onset_response([bad], 100)
    bad = trial.inputs() | {"force": trial.force.iloc[:-1]}
    with pytest.raises(LoperInputError, match="differs from the angles' frames"):
        subject_onset_response([bad], 100)
    with pytest.raises(LoperInputError, match="S01: trial name 'walk-1' appears twice"):
        subject_onset_response([trial.inputs(), trial.inputs()], 100, source="S01")


def test_counts_carry_the_longest_swing_after_an_onset(rng):
    """Perturbed swings of 60, 62, 59 and 61 frames, onsets 13 frames after toe-off: 49 frames are left at most;
    a nominal onset later than the planted one counts instead (240 ms: 62 / 128 - 0.24 s, all too short)."""
    trial, _ = twin_trial(rng)
    _, counts, _ = subject_onset_response([trial.inputs()], 100, MATCHED)
    assert counts.attrs["longest_swing_after_onset_s"] == pytest.approx(49 / RATE, abs=1e-12)
    with pytest.warns(TooFewStridesWarning):
        _, late, _ = subject_onset_response([trial.inputs()], 240, MATCHED)
    assert late.attrs["longest_swing_after_onset_s"] == pytest.approx(62 / RATE - 0.24, abs=1e-12)
    assert late.set_index("trial").loc["total", "n_too_short"] == 4
