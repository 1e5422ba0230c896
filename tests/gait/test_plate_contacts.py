"""Loaded periods of one force plate (loper_analysis.gait.plate_contacts): contacts at the analytic threshold
crossings above the resting level, those cut by the recording marked, on a split-belt walk with known answers."""

import numpy as np
import pytest

from loper_analysis.gait.plate_contacts import plate_contacts
from tests.gait.belt_walk import HAND, PEAK_N, SETTINGS, belt_steps, belt_walk, crossings, plates_above_rest


@pytest.fixture(scope="module")
def trial():
    return belt_walk(np.random.default_rng(20240612))


def test_plate_contacts_fall_on_the_analytic_crossings_above_the_resting_level(trial):
    t, raw, *_ = trial
    plate = plates_above_rest(t, raw)[0]
    found = plate_contacts(plate.time_s, plate.vertical_force_n, **SETTINGS)
    left = [(hs, to) for side, p, hs, to in belt_steps() if p == 1]
    expected = sorted([crossings(hs, to, PEAK_N) for hs, to in left] + [crossings(*HAND)])
    assert len(found) == len(expected) == 10
    start = found["start_s"].to_numpy()
    end = found["end_s"].to_numpy()
    err = np.abs(np.concatenate([start - [e[0] for e in expected], end - [e[1] for e in expected]]))
    assert err.max() < 0.005  # measured: at most 1.2 ms with 2 N noise
    assert not found["incomplete"].any()
    # thresholds on the raw force (rest -40 N not removed) act 40 N higher: heel strikes ~13 ms late
    raw_found = plate_contacts(t, raw[1], **SETTINGS)
    late = raw_found["start_s"].to_numpy() - start
    assert late.min() > 0.010


def test_plate_contacts_mark_contacts_cut_by_the_recording(trial):
    t, raw, *_ = trial
    plate = plates_above_rest(t, raw)[1]
    found = plate_contacts(plate.time_s, plate.vertical_force_n, **SETTINGS)
    # loaded at t = 0 (right stance -0.25 .. 0.45 s) and at the end (10.75 .. 11.45 s)
    assert found["incomplete"].tolist()[0] and found["incomplete"].tolist()[-1]
    assert found["start_sample"].iloc[0] == 0 and found["end_sample"].iloc[-1] == t.size - 1
    assert abs(found["end_s"].iloc[0] - crossings(-0.25, 0.45, PEAK_N)[1]) < 0.005
    assert not found["incomplete"].iloc[1:-1].any()
    # never loaded: no contact; loaded throughout: one incomplete contact
    assert plate_contacts(t, np.zeros(t.size)).empty
    whole = plate_contacts(t, np.full(t.size, 300.0))
    assert whole[["start_sample", "end_sample"]].values.tolist() == [[0, t.size - 1]] and whole["incomplete"].all()
    # a 50 ms unloading is shorter than min_swing_s (0.2 s): still one contact over the whole recording
    blip = np.full(t.size, 300.0)
    blip[1000:1100] = 0.0
    assert plate_contacts(t, blip)[["start_sample", "end_sample"]].values.tolist() == [[0, t.size - 1]]
