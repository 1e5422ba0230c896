"""loper_analysis.impedance.responses.matching: too-short strides and the matched unperturbed stride (also null pairs),
on swing-locked synthetic strides whose twins are known (tests.impedance.responses.twin_strides)."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.responses import MATCH_COLUMNS, match_unperturbed, too_short
from tests.impedance.responses.twin_strides import (
    BUMP_AMP,
    DELAY,
    JOINT_COLS,
    RATE,
    expected_match,
    null_trial,
    twin_trial,
)

#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 20240612


def test_match_picks_exact_twin_at_toe_off_aligned_anchor(rng):
    trial, offsets = twin_trial(
        rng, amplitudes={4: BUMP_AMP, 8: BUMP_AMP, 12: BUMP_AMP, 16: BUMP_AMP, 20: BUMP_AMP}
    )  # stride 20 has no twin
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
    np.testing.assert_allclose(
        m["matched_anchor_s"].to_numpy(), to[m["matched_stride"]].to_numpy() + DELAY / RATE, rtol=0, atol=1e-12
    )
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


def test_too_short_for_the_300_ms_onset():
    table = pd.DataFrame(
        {
            "stride": [0, 1, 2, 3, 4],
            "toe_off_s": [10.0] * 5,
            "swing_s": [0.5, 0.55, 0.56, 0.3, 0.552],
            "perturbed": [True, True, True, False, True],
            "onset_s": [10.3, 10.3, 10.3, np.nan, 10.3046875],  # the last one flagged 4.7 ms late
        }
    )
    np.testing.assert_array_equal(too_short(table, 0.3, 0.25), [True, False, False, False, True])
    np.testing.assert_array_equal(too_short(table, None, 0.25), [True, False, False, False, True])
    late = table.assign(onset_s=[10.3, 10.3, 10.3, np.nan, 10.3])
    np.testing.assert_array_equal(too_short(late, 0.3, 0.25), [True, False, False, False, False])
    with pytest.raises(LoperInputError, match="perturbed stride 1 has onset_s = nan"):
        too_short(table.assign(onset_s=[10.3, np.nan, 10.3, np.nan, 10.3]), 0.3, 0.25)


def test_null_pairs_match_each_unperturbed_stride_to_its_twin_never_itself_or_a_perturbed_one(rng):
    trial, twin = null_trial(rng)
    t = trial.angles["time_s"].to_numpy()
    m = match_unperturbed(
        t,
        trial.angles[JOINT_COLS].to_numpy(),
        trial.strides,
        onset_after_toe_off_s=DELAY / RATE,
        span_s=(-0.125, 0.25),
        missing="drop",
        null_pairs=True,
    )
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
