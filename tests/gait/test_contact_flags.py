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
    WALK_SEED,
    belt_steps,
    belt_walk,
    crossings,
    heel_path,
    hump,
    judged_walk,
    plates_above_rest,
)


@pytest.fixture(scope="module")
def trial():
    return belt_walk(np.random.default_rng(WALK_SEED))


@pytest.fixture(scope="module")
def judged(trial):
    return judged_walk(trial)


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


# One 0.5 m x 0.6 m plate, markers at 100 Hz, a contact loaded 0.4-1.0 s; the feet stand still, the centre of
# pressure (COP) is given: where the plate takes its first load, and whether its load stays under one foot.
_PLATE = np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0], [0.5, 0.6, 0.0], [0.0, 0.6, 0.0]])


def _one_plate(feet, cop_at, end_s=1.0):
    """Contacts of one plate loaded 0.4-``end_s`` s; ``feet``: {side: (heel xyz, toe xyz)}; ``cop_at(t)``: the
    COP (n, 3) at the analog times, or None for a plate without one."""
    t = np.arange(int(1.6 * 1000)) / 1000.0
    tm = np.arange(int(1.6 * 100)) / 100.0
    heels = {s: np.tile(h, (tm.size, 1)) for s, (h, _) in feet.items()}
    toes = {s: np.tile(e, (tm.size, 1)) for s, (_, e) in feet.items()}
    plate = PlateForce(1, t, hump(t, 0.4, end_s, PEAK_N), _PLATE, None if cop_at is None else cop_at(t))
    return foot_contacts([plate], tm, heels, toes_m=toes, vertical_axis=2, **SETTINGS)


def test_a_heel_well_off_the_plate_with_the_forefoot_taking_the_first_load_stays_off_plate():
    feet = {"left": ([-0.135, 0.3, 0.03], [0.045, 0.3, 0.02]), "right": ([-0.8, 0.1, 0.03], [-0.62, 0.1, 0.02])}
    found = _one_plate(feet, lambda t: np.tile([0.03, 0.3, 0.0], (t.size, 1)))  # under the left toe
    r = found.iloc[0]
    assert (r["side"], r["flag"]) == ("left", "off_plate")
    assert r["left_heel_outside_m"] == pytest.approx(0.135)
    assert r["reason"].startswith("heel off the plate's edge: the left heel 135 mm off it at 0.464 s, and")
    assert "165 mm from the left heel marker, nearest the left toe marker (15 mm from the left toe)" in r["reason"]


def test_a_heel_past_the_margin_that_takes_the_first_load_at_the_plate_s_edge_is_on_the_plate():
    """The heel marker 40 mm behind the plate (beyond ``margin_m``, 30 mm) and the first load at the plate's edge
    under it, 45 mm ahead of the marker: the heel landed on the plate. Without a COP the margin alone decides."""
    feet = {"left": ([-0.04, 0.3, 0.03], [0.14, 0.3, 0.02]), "right": ([-0.8, 0.1, 0.03], [-0.62, 0.1, 0.02])}
    rolling = lambda t: np.column_stack([np.interp(t, [0.4, 1.0], [0.005, 0.16]), np.full(t.size, 0.3), 0 * t])  # noqa: E731
    found = _one_plate(feet, rolling)
    assert found[["side", "flag", "reason"]].values.tolist() == [["left", "ok", ""]]
    ev = contact_events(found)
    assert ev["event"].tolist() == ["heel_strike", "toe_off"]
    blind = _one_plate(feet, None)
    assert blind[["side", "flag"]].values.tolist() == [["left", "off_plate"]]
    assert (
        blind["reason"].iloc[0].startswith("heel off the plate's edge: the left heel 40 mm off it at 0.464 s; the foot")
    )


# The left foot stands on the plate from 0.4 s; the right heel and toe stand on it too (0.15 m to its right).
_TWO = {"left": ([0.10, 0.15, 0.03], [0.28, 0.15, 0.02]), "right": ([0.25, 0.40, 0.03], [0.43, 0.40, 0.02])}


def test_two_feet_loading_one_plate_stay_two_feet_with_the_centre_of_pressure_in_the_reason():
    """The load passes from under the left foot (0.19, 0.15) to under the right one (0.34, 0.40), 0.6-1.2 s."""
    moving = lambda t: np.column_stack(  # noqa: E731
        [np.interp(t, [0.6, 1.2], [0.19, 0.34]), np.interp(t, [0.6, 1.2], [0.15, 0.40]), 0 * t]
    )
    found = _one_plate(_TWO, moving, end_s=1.3)
    r = found.iloc[0]
    assert (r["flag"], r["side"]) == ("two_feet", "")  # both heels on it at the start probe
    # 0.471 s: the start probe's time, sample instants of a built force (arithmetic, not a solver's output)
    assert r["reason"] == "two feet on one plate: both heels on it at 0.471 s"
    # the right foot arrives at 0.7 s (in the air over the plate before): its stay makes it a second foot
    late = {"left": _TWO["left"], "right": _TWO["right"]}
    tm = np.arange(160) / 100.0
    heels = {s: np.tile(h, (tm.size, 1)) for s, (h, _) in late.items()}
    toes = {s: np.tile(e, (tm.size, 1)) for s, (_, e) in late.items()}
    heels["right"][tm < 0.7, 2] = toes["right"][tm < 0.7, 2] = 0.2
    t = np.arange(1600) / 1000.0
    plate = PlateForce(1, t, hump(t, 0.4, 1.3, PEAK_N), _PLATE, moving(t))
    r = foot_contacts([plate], tm, heels, toes_m=toes, vertical_axis=2, **SETTINGS).iloc[0]
    assert (r["side"], r["flag"]) == ("left", "two_feet")
    # 0.9 s: halfway, 0.125 m off both feet's heel-toe lines; 1.242 s: the end probe
    said = "two feet on one plate: the right heel stands on it from 0.700 to 1.242 s while the left foot is on it; "
    assert r["reason"] == said + "the plate's centre of pressure nearer the right foot than the left foot at 0.900 s"
    # the same feet, the load under the left foot throughout (heel to toe): the right foot carries nothing here
    under_left = lambda t: np.column_stack([np.interp(t, [0.4, 1.3], [0.11, 0.28]), np.full(t.size, 0.15), 0 * t])  # noqa: E731
    alone = PlateForce(1, t, hump(t, 0.4, 1.3, PEAK_N), _PLATE, under_left(t))
    r = foot_contacts([alone], tm, heels, toes_m=toes, vertical_axis=2, **SETTINGS).iloc[0]
    assert (r["side"], r["flag"], r["reason"]) == ("left", "ok", "")
    blind = PlateForce(1, t, hump(t, 0.4, 1.3, PEAK_N), _PLATE)
    assert foot_contacts([blind], tm, heels, toes_m=toes, vertical_axis=2, **SETTINGS)["flag"].tolist() == ["two_feet"]


def _lab_walk(lab):
    """A clinical lab's walk: plates as the events job reads them (force above the resting level, COP; lab frame,
    Z up, m), heel and toe markers (m) and each plate's own loaded periods from ezc3d: from the first sample
    >= 50 N above its resting level (the tenth of the samples nearest zero) to the first one <= 20 N after."""
    ezc3d = pytest.importorskip("ezc3d")
    from loper_analysis.gait.grf import plates_loads
    from loper_analysis.io.force_platforms import read_force_platforms

    path = __import__("pathlib").Path(__file__).parents[1] / "data" / "c3d-parser" / lab / "walk-nodevice.c3d"
    c = ezc3d.c3d(str(path), extract_forceplat_data=True)
    prm = c["parameters"]
    labels = [s.strip() for s in prm["POINT"]["LABELS"]["value"]]
    rate, arate = float(prm["POINT"]["RATE"]["value"][0]), float(prm["ANALOG"]["RATE"]["value"][0])
    t0 = c["header"]["points"]["first_frame"] / rate
    points = c["data"]["points"][:3] / 1000.0  # mm -> m
    points[:, np.all(points == 0.0, axis=0)] = np.nan
    tm = t0 + np.arange(points.shape[2]) / rate
    toe = "LA_TOE" if lab == "AUC" else "TOE"
    heels = {s: points[:, labels.index(f"{s[0].upper()}HEE")].T for s in ("left", "right")}
    toes = {s: points[:, labels.index(f"{s[0].upper()}{toe}")].T for s in ("left", "right")}
    loaded = {}
    for k, p in enumerate(c["data"]["platform"], start=1):
        fz = np.asarray(p["force"][2], dtype=float)
        f = fz - float(np.median(fz[np.argsort(np.abs(fz))[: fz.size // 10]]))
        f = f if f.max() > -f.min() else -f
        t = t0 + np.arange(f.size) / arate
        on = np.flatnonzero((f[1:] >= 50.0) & (np.maximum.accumulate(f[::-1])[::-1][1:] >= 50.0))
        starts = [i + 1 for i in on if f[: i + 1][-1] < 50.0 and (f[: i + 1] <= 20.0).any()]
        loaded[k] = [(t[i], t[i + np.flatnonzero(f[i:] <= 20.0)[0]]) for i in starts if (f[i:] <= 20.0).any()]
    loads = plates_loads(read_force_platforms(path), 20.0, 10.0, 100.0)
    plates = [PlateForce(p.number, p.time_s, p.force_n[:, 2], p.corners_m, p.cop_m) for p in loads]
    return plates, tm, heels, toes, loaded


@pytest.mark.parametrize(
    ("lab", "plate", "loaded_s"),
    [("AUC", 2, (1.067, 1.525)), ("RCH", 5, (5.881, 6.544))],
)
def test_clinical_labs_contacts_once_lost_give_events_at_the_plates_own_loading(lab, plate, loaded_s):
    """AUC plate 2: the left heel marker 30 mm behind the plate, the plate's first load 48 mm ahead of it (nearest
    the left heel of the four foot markers): the heel landed on the plate. RCH plate 5: the right heel in the seam
    between plates 4 and 5 while plate 5's load stays under the left foot: one foot on it. Every contact of both
    walks is clean, with its heel strike and toe-off within 15 ms of its plate's own loading and unloading."""
    plates, tm, heels, toes, loaded = _lab_walk(lab)
    found = foot_contacts(plates, tm, heels, toes_m=toes, vertical_axis=2, source=lab)
    assert (found["flag"] == "ok").all(), found[["plate", "flag", "reason"]].values.tolist()
    np.testing.assert_allclose(loaded[plate], [loaded_s], atol=0.001)
    ev = contact_events(found)
    for r in found.itertuples():
        ((on, off),) = loaded[r.plate]
        mine = ev[ev["side"] == r.side].set_index("event")["time_s"]
        assert (abs(mine["heel_strike"] - on) <= 0.015).any() and (abs(mine["toe_off"] - off) <= 0.015).any()
    lost = found[found["plate"] == plate].iloc[0]
    assert lost["side"] == "left"
    if lab == "AUC":
        assert lost["left_heel_outside_m"] == pytest.approx(0.0303, abs=0.0005)
