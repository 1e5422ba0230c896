"""Perturbation responses against known answers: planted bumps on swing-locked synthetic strides.

Every stride's joint angles are one smooth curve of the time since its own
toe-off plus a per-stride offset, so two strides with equal offsets are exact
twins once aligned at their toe-offs. Perturbed strides get a known bump after
the onset (and a 40 N pulse on the force); all event times are 128 Hz frames,
so the windows sample frames and the planted answers come back to round-off.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.dynamics import joint_angles, segment_coordinates, segment_parameters_from_anthropometry
from loper_analysis.errors import LoperInputError
from loper_analysis.gait import TooFewStridesWarning, window_times_s
from loper_analysis.identification import prepare_window
from loper_analysis.responses import (
    COUNT_COLUMNS,
    MATCH_COLUMNS,
    match_unperturbed,
    null_pair_windows,
    paired_windows,
    subject_onset_response,
    too_short,
    window_outliers,
)
from loper_analysis.synthetic.response import thigh_normal

RATE = 128.0
DELAY = 13  # onset 13 frames (101.6 ms) after toe-off: the first flagged frame of a 100 ms onset
BUMP_AMP = np.array([0.1, 0.2, 0.05])  # rad, hip knee ankle
PULSE_N = 40.0
JOINT_COLS = [f"{j}_left_rad" for j in JOINTS]


@pytest.fixture
def rng():
    return np.random.default_rng(20240612)


def swing_curve(tau):
    """Smooth joint angles (n, 3), rad, as a function of the time since toe-off (s)."""
    return np.stack([
        0.4 * np.sin(2 * np.pi * tau / 1.1 + 0.3),
        0.6 * np.sin(2 * np.pi * tau / 0.9 + 1.0),
        0.2 * np.sin(2 * np.pi * tau / 1.3 - 0.5),
    ], axis=-1)


def bump(tau):
    """Planted response shape: sin^2 over 0 .. 0.3 s after the onset, 0 elsewhere."""
    return np.where((tau > 0) & (tau < 0.3), np.sin(np.pi * tau / 0.3) ** 2, 0.0)


@dataclass
class Trial:
    name: str
    angles: pd.DataFrame
    force: pd.DataFrame
    direction: np.ndarray
    strides: pd.DataFrame
    toe_off: np.ndarray  # frame index of each stride's toe-off
    onset: dict  # perturbed stride -> onset frame

    def inputs(self) -> dict:
        return {"name": self.name, "angles": self.angles, "strides": self.strides, "force": self.force,
                "force_direction": self.direction}


def make_trial(name, stance, swing, offsets, perturbed, removed=(), lead=40, tail=60) -> Trial:
    """Trial with strides of ``stance`` + ``swing`` frames; ``perturbed``: stride -> bump amplitudes (3,)."""
    stance, swing = np.asarray(stance), np.asarray(swing)
    n_strides = stance.size
    hs = lead + np.concatenate([[0], np.cumsum(stance + swing)])
    to = hs[:-1] + stance
    n = int(hs[-1]) + tail
    frame = np.arange(n)
    t = frame / RATE
    sid = np.clip(np.searchsorted(hs, frame, side="right") - 1, 0, n_strides - 1)
    tau = (frame - to[sid]) / RATE
    angles = swing_curve(tau) + np.asarray(offsets)[sid]
    pelvis = 0.05 * np.sin(2 * np.pi * tau) + 0.001 * sid
    pelvis_x = 0.02 * np.cos(2 * np.pi * tau / 1.2)
    force = 2.0 + 0.5 * np.cos(2 * np.pi * tau)
    onset_s = np.full(n_strides, np.nan)
    onsets = {}
    for s, amp in perturbed.items():
        k0 = int(to[s] + DELAY)
        angles = angles + np.asarray(amp) * bump((frame - k0) / RATE)[:, None]
        force = force + PULSE_N * ((frame >= k0) & (frame < k0 + 13))
        onset_s[s] = t[k0]
        onsets[s] = k0
    q = segment_coordinates(angles, pelvis, pelvis_x)
    direction = thigh_normal(q[:, 1])
    table = pd.DataFrame({
        "stride": np.arange(n_strides), "side": "left",
        "heel_strike_s": t[hs[:-1]], "toe_off_s": t[to], "end_s": t[hs[1:]],
        "duration_s": (hs[1:] - hs[:-1]) / RATE, "stance_s": stance / RATE, "swing_s": swing / RATE,
        "perturbed": np.isfinite(onset_s), "onset_s": onset_s,
        "removed": np.isin(np.arange(n_strides), list(removed)), "reason": "",
    })
    frame_angles = pd.DataFrame({"time_s": t, "pelvis_x_m": pelvis_x, "pelvis_angle_rad": pelvis})
    for j, c in enumerate(JOINT_COLS):
        frame_angles[c] = angles[:, j]
    frame_force = pd.DataFrame({"time_s": t, "force_measured_n": force, "force_desired_n": 0.0, "perturbation": 0})
    return Trial(name, frame_angles, frame_force, direction, table, to, onsets)


def twin_trial(rng, name="walk-1", twins=None, amplitudes=None, removed=(), short=(), n_strides=26):
    """Strides with varied stance and swing (``short``: 40-frame swings) and random offsets;
    each perturbed stride in ``twins`` has a twin."""
    twins = {4: 1, 8: 6, 12: 10, 16: 14} if twins is None else twins
    i = np.arange(n_strides)
    stance, swing = 88 + (7 * i) % 5, np.where(np.isin(i, list(short)), 40, 58 + (3 * i) % 5)
    offsets = rng.uniform(-0.05, 0.05, (n_strides, 3))
    for p, u in twins.items():
        offsets[u] = offsets[p]
    if amplitudes is None:
        amplitudes = {p: BUMP_AMP * (1.0 + 0.1 * k) for k, p in enumerate(sorted(twins))}
    return make_trial(name, stance, swing, offsets, amplitudes, removed=removed), offsets


def expected_match(trial, offsets, p, excluded=()):
    """Brute force: the allowed unperturbed stride of least RMS offset difference (the shapes coincide)."""
    table = trial.strides
    cand = np.flatnonzero(~table["perturbed"].to_numpy() & ~table["removed"].to_numpy())
    cand = np.array([c for c in cand if c not in excluded])
    rmsd = np.sqrt(np.mean((offsets[cand] - offsets[p]) ** 2, axis=1))
    return int(cand[np.argmin(rmsd)]), float(rmsd.min())


# --------------------------------------------------------------------------- matching


def test_match_picks_exact_twin_at_toe_off_aligned_anchor(rng):
    trial, offsets = twin_trial(rng, amplitudes={4: BUMP_AMP, 8: BUMP_AMP, 12: BUMP_AMP, 16: BUMP_AMP,
                                                 20: BUMP_AMP})  # stride 20 has no twin
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides, source="walk-1")
    assert list(m.columns) == list(MATCH_COLUMNS)
    assert m["stride"].tolist() == [4, 8, 12, 16, 20]
    assert m["matched_stride"].tolist()[:4] == [1, 6, 10, 14]
    np.testing.assert_allclose(m["rmsd_rad"].to_numpy()[:4], 0.0, atol=1e-12)
    # without a twin: the least offset difference, and its RMSD over the three joints
    want, want_rmsd = expected_match(trial, offsets, 20)
    assert m["matched_stride"].iloc[4] == want
    np.testing.assert_allclose(m["rmsd_rad"].iloc[4], want_rmsd, rtol=1e-10)
    # anchor: same time after the candidate's own toe-off (stances differ, so heel strikes would not do)
    to = trial.strides.set_index("stride")["toe_off_s"]
    np.testing.assert_allclose(m["matched_anchor_s"].to_numpy(),
                               to[m["matched_stride"]].to_numpy() + DELAY / RATE, rtol=0, atol=1e-12)
    np.testing.assert_allclose(m["onset_s"] - m["toe_off_s"], DELAY / RATE, atol=1e-12)
    assert (m["n_candidates"] == 26 - 5).all()


def test_match_ignores_removed_candidates(rng):
    trial, offsets = twin_trial(rng, removed=(6,))
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides).set_index("stride")
    want, want_rmsd = expected_match(trial, offsets, 8, excluded=(6,))
    assert m.loc[8, "matched_stride"] == want != 6
    np.testing.assert_allclose(m.loc[8, "rmsd_rad"], want_rmsd, rtol=1e-10)
    assert not set(m["matched_stride"]) & {4, 8, 12, 16}  # never a perturbed stride


def test_match_skips_candidates_whose_window_leaves_the_data(rng):
    trial, _ = twin_trial(rng, twins={4: 0})  # the twin is the first stride, 1.1 s into the data
    t = trial.angles["time_s"].to_numpy()
    x = trial.angles[JOINT_COLS].to_numpy()
    assert match_unperturbed(t, x, trial.strides)["matched_stride"].iloc[0] == 0
    m = match_unperturbed(t, x, trial.strides, span_s=(-1.5, 0.25))
    assert m["matched_stride"].iloc[0] != 0
    assert m["n_candidates"].iloc[0] == 26 - 1 - 1


def test_match_without_candidate_names_stride_and_source(rng):
    trial, _ = twin_trial(rng, twins={4: 1}, removed=[s for s in range(26) if s != 4])
    t = trial.angles["time_s"].to_numpy()
    x = trial.angles[JOINT_COLS].to_numpy()
    with pytest.raises(LoperInputError, match=r"walk-1: perturbed stride 4 has no unperturbed match"):
        match_unperturbed(t, x, trial.strides, source="walk-1")
    m = match_unperturbed(t, x, trial.strides, source="walk-1", missing="drop")
    assert m.empty and list(m.attrs["unmatched"]) == [4]


def test_match_leaves_out_too_short_strides(rng):
    trial, _ = twin_trial(rng)
    trial.strides.loc[8, "swing_s"] = 0.3  # shorter than 101.6 ms + 250 ms
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides, window_after_s=0.25)
    assert m["stride"].tolist() == [4, 12, 16] and m.attrs["too_short"] == [8]


# --------------------------------------------------------------------------- too short


def test_too_short_for_the_300_ms_onset():
    table = pd.DataFrame({
        "stride": [0, 1, 2, 3, 4],
        "toe_off_s": [10.0] * 5,
        "swing_s": [0.5, 0.55, 0.56, 0.3, 0.552],
        "perturbed": [True, True, True, False, True],
        "onset_s": [10.3, 10.3, 10.3, np.nan, 10.3046875],  # the last one flagged 4.7 ms late
    })
    np.testing.assert_array_equal(too_short(table, 0.3, 0.25), [True, False, False, False, True])
    np.testing.assert_array_equal(too_short(table, None, 0.25), [True, False, False, False, True])
    late = table.assign(onset_s=[10.3, 10.3, 10.3, np.nan, 10.3])
    np.testing.assert_array_equal(too_short(late, 0.3, 0.25), [True, False, False, False, False])
    with pytest.raises(LoperInputError, match="perturbed stride 1 has onset_s = nan"):
        too_short(table.assign(onset_s=[10.3, np.nan, 10.3, np.nan, 10.3]), 0.3, 0.25)


# --------------------------------------------------------------------------- windows


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


# --------------------------------------------------------------------------- outliers


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


# --------------------------------------------------------------------------- subject average


def test_subject_response_returns_the_planted_bump(rng):
    amplitudes = {4: 1.0, 8: 1.1, 12: 1.3, 16: 0.8}
    trial, _ = twin_trial(rng, amplitudes={p: BUMP_AMP * a for p, a in amplitudes.items()})
    response, counts, series = subject_onset_response([trial.inputs()], 100, min_strides=4)
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
        series["time_s"], series["q_unperturbed"], series["q_perturbed"],
        segment_parameters_from_anthropometry(1.75, 70.0), series["onset_s"],
        force_unperturbed_n=series["force_unperturbed_n"], force_perturbed_n=series["force_perturbed_n"],
        pelvis_angle_unperturbed_rad=series["pelvis_angle_unperturbed_rad"],
        pelvis_angle_perturbed_rad=series["pelvis_angle_perturbed_rad"],
        window_before_s=series["window_before_s"], window_after_s=series["window_after_s"],
        initial_state_span_s=series["initial_state_span_s"],
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
    trial_a, _ = twin_trial(rng, "walk-1", twins={4: 1, 8: 6, 12: 10, 16: 14, 20: 18}, amplitudes=amplitudes,
                            short=(22,))
    j = np.arange(8)
    trial_b = make_trial("walk-2", 88 + j % 3, 60 + j % 2, rng.uniform(-0.05, 0.05, (8, 3)),
                         {3: BUMP_AMP, 6: BUMP_AMP}, removed=[s for s in range(8) if s not in (3, 6)])
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
    np.testing.assert_allclose(response["hip_rad_mean"], np.mean(list(good.values())) * BUMP_AMP[0]
                               * bump(response["time_s"].to_numpy()), atol=1e-9)
    _, counts, _ = subject_onset_response([trial_a.inputs(), trial_b.inputs()], 100, min_strides=4)
    assert counts["status"].tolist() == ["ok", "too_few_strides", "ok"]


def test_subject_response_with_no_pair_is_nan_not_a_crash(rng):
    j = np.arange(8)
    trial = make_trial("walk-2", 88 + j % 3, 60 + j % 2, rng.uniform(-0.05, 0.05, (8, 3)), {3: BUMP_AMP},
                       removed=[s for s in range(8) if s != 3])
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


# --------------------------------------------------------------------------- null pairs


def null_trial(rng):
    """Unperturbed strides in twin pairs (equal offsets); perturbed strides 4 and 8 copy stride 10's
    offsets, so a stride 10 that could match them would tie with them (and ties go to the first)."""
    n = 16
    i = np.arange(n)
    stance, swing = 88 + (7 * i) % 5, 58 + (3 * i) % 5
    offsets = rng.uniform(-0.05, 0.05, (n, 3))
    twins = {0: 1, 2: 3, 5: 6, 7: 9, 10: 11, 12: 13, 14: 15}
    for a, b in twins.items():
        offsets[b] = offsets[a]
    offsets[4] = offsets[8] = offsets[10]
    trial = make_trial("walk-n", stance, swing, offsets, {4: BUMP_AMP, 8: BUMP_AMP})
    return trial, {**twins, **{b: a for a, b in twins.items()}}


def test_null_pairs_match_each_unperturbed_stride_to_its_twin_never_itself_or_a_perturbed_one(rng):
    trial, twin = null_trial(rng)
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides, onset_after_toe_off_s=DELAY / RATE,
                          span_s=(-0.125, 0.25), missing="drop", null_pairs=True)
    assert len(m) >= 12  # every stride but those whose window leaves the data
    assert not set(m["stride"]) & {4, 8} and not set(m["matched_stride"]) & {4, 8}
    for s, u in zip(m["stride"], m["matched_stride"]):
        assert u == twin[s], (s, u)
    np.testing.assert_allclose(m["rmsd_rad"], 0.0, atol=1e-12)
    # the nominal onset: DELAY frames after each stride's own toe-off
    toe = trial.strides.set_index("stride")["toe_off_s"]
    np.testing.assert_allclose(m["onset_s"], toe[m["stride"]].to_numpy() + DELAY / RATE, atol=1e-12)
    with pytest.raises(LoperInputError, match="null_pairs needs onset_after_toe_off_s"):
        match_unperturbed(t, trial.angles[JOINT_COLS].to_numpy(), trial.strides, null_pairs=True)


def test_null_pair_windows_of_twins_are_identical_and_pool_trials(rng):
    """Twin pairs differ by nothing: zero differences in every coordinate; two trials pool their pairs."""
    a, _ = null_trial(rng)
    b, _ = null_trial(rng)
    b.name = "walk-m"
    out = null_pair_windows([a.inputs(), b.inputs()], DELAY / RATE * 1e3, RATE, source="S01")
    single = null_pair_windows([a.inputs()], DELAY / RATE * 1e3, RATE)
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
