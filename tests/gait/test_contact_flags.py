"""The foot, flag and reason of each force-plate contact (loper_analysis.gait.contact_flags), through the contact
table of a split-belt walk with known answers: every flag, the belt map only a check, a crossover step."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import CONTACT_FLAGS
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.contacts import CONTACT_COLUMNS, PlateForce, contact_events, foot_contacts
from loper_analysis.gait.events import flagged_contacts
from tests.gait.belt_walk import (
    CORNERS,
    DURATION_S,
    FS,
    HAND,
    MARKER_HZ,
    PEAK_N,
    SETTINGS,
    belt_steps,
    belt_walk,
    crossings,
    heel_path,
    hump,
    plates_above_rest,
)


@pytest.fixture(scope="module")
def trial():
    return belt_walk(np.random.default_rng(20240612))


@pytest.fixture(scope="module")
def judged(trial):
    t, raw, tm, heels, _ = trial
    return foot_contacts(plates_above_rest(t, raw), tm, heels, **SETTINGS, source="S01/walk")


def test_every_contact_gets_its_known_foot_and_flag(judged):
    assert list(judged.columns) == list(CONTACT_COLUMNS)
    assert set(judged["flag"]) <= set(CONTACT_FLAGS)
    # known answer per contact: (plate, analytic start crossing, side, flag)
    expected = []
    for side, plate, hs, to in belt_steps():
        merged = plate == 2 and 5.2 < hs < 6.4  # right 5.25 s + left crossover 5.8 s + right 6.35 s
        if hs < 0:
            expected.append((2, 0.0, "right", "incomplete"))  # loaded when the recording starts
        elif to > DURATION_S:
            expected.append((2, crossings(hs, to, PEAK_N)[0], "right", "incomplete"))
        elif merged and hs < 5.3:
            expected.append((2, crossings(hs, to, PEAK_N)[0], "right", "two_feet"))
        elif not merged:
            if abs(hs - 8.55) < 1e-9:  # the right heel is missing at the start probe: foot unknown
                expected.append((2, crossings(hs, to, PEAK_N)[0], "", "heel_missing"))
            else:
                expected.append((plate, crossings(hs, to, PEAK_N)[0], side, "ok"))
    # the hand load: the left heel is up in swing over plate 1, the right one stands on plate 2
    expected.append((1, crossings(*HAND)[0], "", "no_foot"))
    expected.sort(key=lambda e: (e[1], e[0]))
    assert len(judged) == len(expected) == 20
    for r, (plate, start, side, flag) in zip(judged.itertuples(), expected):
        assert (r.plate, r.side, r.flag) == (plate, side, flag)
        assert abs(r.start_s - start) < 0.005
    ok = judged[judged["flag"] == "ok"]
    assert len(ok) == 15 and (ok["side"] == np.where(ok["plate"] == 1, "left", "right")).all()


def test_belt_map_is_only_a_check(trial, judged):
    t, raw, tm, heels, _ = trial
    plates = plates_above_rest(t, raw)
    same = foot_contacts(plates, tm, heels, plate_sides={"left": 1, "right": 2}, **SETTINGS)
    pd.testing.assert_frame_equal(same.drop(columns="belt_side"), judged.drop(columns="belt_side"))
    assert (same["belt_side"] == np.where(same["plate"] == 1, "left", "right")).all()
    swapped = foot_contacts(plates, tm, heels, plate_sides={"left": 2, "right": 1}, **SETTINGS)
    assert (swapped.loc[judged["flag"] == "ok", "flag"] == "wrong_belt").all()
    assert (swapped["side"] == judged["side"]).all()  # the markers still name the foot
    ev = contact_events(swapped)
    assert not ev["event"].isin(["heel_strike", "toe_off"]).any()
    assert flagged_contacts(ev) == len(swapped)
    with pytest.raises(LoperInputError, match="plate 3"):
        foot_contacts(plates, tm, heels, plate_sides={"left": 3}, **SETTINGS)


def test_a_single_crossover_step_alone_on_the_other_belt_is_assigned_by_the_markers():
    t = np.arange(int(3.0 * FS)) / FS
    tm = np.arange(int(3.0 * MARKER_HZ)) / MARKER_HZ
    steps = [("left", 1, 0.3, 1.0), ("left", 2, 1.6, 2.3)]  # the right foot stays off both plates
    f = {1: hump(t, 0.3, 1.0, PEAK_N), 2: hump(t, 1.6, 2.3, PEAK_N)}
    heels = {"left": heel_path("left", steps, tm), "right": np.tile([0.0, -0.5, 0.05], (tm.size, 1))}
    plates = [PlateForce(p, t, f[p], CORNERS[p]) for p in (1, 2)]
    free = foot_contacts(plates, tm, heels)
    assert free[["plate", "side", "flag"]].values.tolist() == [[1, "left", "ok"], [2, "left", "ok"]]
    mapped = foot_contacts(plates, tm, heels, plate_sides={"left": 1, "right": 2})
    assert mapped["flag"].tolist() == ["ok", "wrong_belt"]
    ev = contact_events(mapped)
    assert ev["event"].tolist() == ["heel_strike", "toe_off", "flagged_start", "flagged_end"]
    assert (ev["side"] == "left").all()
