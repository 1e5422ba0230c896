"""Force-plate contacts, the foot on each, flags, events and strides: a split-belt treadmill with known answers."""

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import CONTACT_FLAGS
from loper_analysis.errors import LoperInputError
from loper_analysis.gait.contacts import (
    CONTACT_COLUMNS,
    PlateForce,
    contact_events,
    foot_contacts,
    plate_contacts,
)
from loper_analysis.gait.events import EVENT_COLUMNS, flagged_contacts, gait_events
from loper_analysis.gait.plate_geometry import plate_offsets
from loper_analysis.gait.strides import strides_from_events

FS = 2000.0  # analog rate, Hz
MARKER_HZ = 200.0
DURATION_S = 11.0
PEAK_N = 700.0
STANCE_S = 0.7
PERIOD_S = 1.1
REST_N = -40.0  # unloaded plates read this (not zeroed)
ON_N, OFF_N = 50.0, 20.0
SETTINGS = {"threshold_on_n": ON_N, "threshold_off_n": OFF_N, "min_stance_s": 0.08, "min_swing_s": 0.08}
# plate 1 under the left belt, plate 2 under the right one (walking along +y, surface z = 0)
CORNERS = {
    1: np.array([[-0.50, 0.0, 0.0], [-0.01, 0.0, 0.0], [-0.01, 1.6, 0.0], [-0.50, 1.6, 0.0]]),
    2: np.array([[0.01, 0.0, 0.0], [0.50, 0.0, 0.0], [0.50, 1.6, 0.0], [0.01, 1.6, 0.0]]),
}
HEEL_X = {1: -0.15, 2: 0.15}
CROSSOVER_X = 0.20  # the left foot's crossover step lands here, on the right belt
HAND = (2.22, 2.38, 150.0)  # a hand (object) load on plate 1 in the left swing: start, end, peak
MISSING = (8.60, 8.63)  # the right heel is missing around the start probe of its contact at 8.55 s (8.617 s)


def _steps():
    """(side, plate, heel strike s, toe-off s) of every foot contact; left step 5 crosses over to plate 2."""
    out = []
    for k in range(10):
        out.append(("left", 2 if k == 5 else 1, 0.3 + PERIOD_S * k, 0.3 + PERIOD_S * k + STANCE_S))
    for k in range(-1, 10):
        out.append(("right", 2, 0.85 + PERIOD_S * k, 0.85 + PERIOD_S * k + STANCE_S))
    return out


def _hump(t, start, end, peak):
    inside = (t >= start) & (t <= end)
    return np.where(inside, peak * np.sin(np.pi * np.clip((t - start) / (end - start), 0, 1)), 0.0)


def _crossings(start, end, peak):
    """Analytic times where a half-sine hump rises through ON_N and falls through OFF_N."""
    d = end - start
    return start + d / math.pi * math.asin(ON_N / peak), end - d / math.pi * math.asin(OFF_N / peak)


def _heel(side, steps, t):
    """Heel marker (n, 3) in m: on its plate in stance (moving back with the belt), arcs up to 0.2 m in swing."""
    mine = sorted((s for s in steps if s[0] == side), key=lambda s: s[2])
    xyz = np.zeros((t.size, 3))
    first_x = CROSSOVER_X if (side == "left" and mine[0][1] == 2) else HEEL_X[mine[0][1]]
    xyz[t < mine[0][2]] = [first_x, 0.7, 0.2]  # in the air before the first step and after the last
    xyz[t > mine[-1][3]] = [HEEL_X[mine[-1][1]], 0.7, 0.2]
    for i, (_, plate, hs, to) in enumerate(mine):
        x = CROSSOVER_X if (side == "left" and plate == 2) else HEEL_X[plate]
        stance = (t >= hs) & (t <= to)
        xyz[stance] = np.column_stack(
            [np.full(stance.sum(), x), 1.1 - 1.0 * (t[stance] - hs), np.full(stance.sum(), 0.05)]
        )
        if i + 1 < len(mine):
            nxt = mine[i + 1]
            x2 = CROSSOVER_X if (side == "left" and nxt[1] == 2) else HEEL_X[nxt[1]]
            swing = (t > to) & (t < nxt[2])
            u = (t[swing] - to) / (nxt[2] - to)
            xyz[swing] = np.column_stack([x + (x2 - x) * u, 0.4 + 0.7 * u, 0.05 + 0.15 * np.sin(np.pi * u)])
    return xyz


def _trial(rng):
    steps = _steps()
    t = np.arange(int(DURATION_S * FS)) / FS
    raw = {1: np.full(t.size, REST_N), 2: np.full(t.size, REST_N)}
    for _, plate, hs, to in steps:
        raw[plate] += _hump(t, hs, to, PEAK_N)
    raw[1] += _hump(t, *HAND)
    for p in raw:
        raw[p] += rng.normal(0.0, 2.0, t.size)
    tm = np.arange(int(DURATION_S * MARKER_HZ)) / MARKER_HZ
    heels = {s: _heel(s, steps, tm) for s in ("left", "right")}
    heels["right"][(tm >= MISSING[0]) & (tm <= MISSING[1])] = np.nan
    return t, raw, tm, heels, steps


def _plates(t, raw):
    """Force above the resting level: the median of a span where each plate is known to be unloaded."""
    quiet = {1: (0.0, 0.25), 2: (0.5, 0.8)}
    out = []
    for p in (1, 2):
        a, b = quiet[p]
        rest = np.median(raw[p][(t >= a) & (t < b)])
        assert abs(rest - REST_N) < 0.3
        out.append(PlateForce(p, t, raw[p] - rest, CORNERS[p]))
    return out


@pytest.fixture(scope="module")
def trial():
    return _trial(np.random.default_rng(20240612))


@pytest.fixture(scope="module")
def judged(trial):
    t, raw, tm, heels, _ = trial
    return foot_contacts(_plates(t, raw), tm, heels, **SETTINGS, source="S01/walk")


def test_plate_contacts_fall_on_the_analytic_crossings_above_the_resting_level(trial):
    t, raw, *_ = trial
    plate = _plates(t, raw)[0]
    found = plate_contacts(plate.time_s, plate.vertical_force_n, **SETTINGS)
    left = [(hs, to) for side, p, hs, to in _steps() if p == 1]
    expected = sorted([_crossings(hs, to, PEAK_N) for hs, to in left] + [_crossings(*HAND)])
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
    plate = _plates(t, raw)[1]
    found = plate_contacts(plate.time_s, plate.vertical_force_n, **SETTINGS)
    # loaded at t = 0 (right stance -0.25 .. 0.45 s) and at the end (10.75 .. 11.45 s)
    assert found["incomplete"].tolist()[0] and found["incomplete"].tolist()[-1]
    assert found["start_sample"].iloc[0] == 0 and found["end_sample"].iloc[-1] == t.size - 1
    assert abs(found["end_s"].iloc[0] - _crossings(-0.25, 0.45, PEAK_N)[1]) < 0.005
    assert not found["incomplete"].iloc[1:-1].any()
    # never loaded: no contact; loaded throughout: one incomplete contact
    assert plate_contacts(t, np.zeros(t.size)).empty
    whole = plate_contacts(t, np.full(t.size, 300.0))
    assert whole[["start_sample", "end_sample"]].values.tolist() == [[0, t.size - 1]] and whole["incomplete"].all()
    # a 50 ms unloading is shorter than min_swing_s (0.2 s): still one contact over the whole recording
    blip = np.full(t.size, 300.0)
    blip[1000:1100] = 0.0
    assert plate_contacts(t, blip)[["start_sample", "end_sample"]].values.tolist() == [[0, t.size - 1]]


def test_bad_input_is_named(trial):
    t, raw, tm, heels, _ = trial
    plates = _plates(t, raw)
    with pytest.raises(LoperInputError, match=r"walk: heels_m\['right'\] must have shape \(2200, 3\)"):
        foot_contacts(plates, tm, {"left": heels["left"], "right": heels["right"][:-1]}, source="walk")
    with pytest.raises(LoperInputError, match=r"plate numbers must be distinct, got \[1, 1\]"):
        foot_contacts([plates[0], plates[0]], tm, heels)
    with pytest.raises(LoperInputError, match="walk: plate 2: corners_m must be a finite"):
        foot_contacts([plates[0], PlateForce(2, t, raw[2], np.zeros((3, 3)))], tm, heels, source="walk")
    with pytest.raises(LoperInputError, match="unknown flag"):
        contact_events(
            pd.DataFrame(
                {
                    "side": ["left"],
                    "flag": ["fine"],
                    "start_s": [0.0],
                    "end_s": [1.0],
                    "start_sample": [0],
                    "end_sample": [9],
                }
            )
        )


def test_every_contact_gets_its_known_foot_and_flag(judged):
    assert list(judged.columns) == list(CONTACT_COLUMNS)
    assert set(judged["flag"]) <= set(CONTACT_FLAGS)
    # known answer per contact: (plate, analytic start crossing, side, flag)
    expected = []
    for side, plate, hs, to in _steps():
        merged = plate == 2 and 5.2 < hs < 6.4  # right 5.25 s + left crossover 5.8 s + right 6.35 s
        if hs < 0:
            expected.append((2, 0.0, "right", "incomplete"))  # loaded when the recording starts
        elif to > DURATION_S:
            expected.append((2, _crossings(hs, to, PEAK_N)[0], "right", "incomplete"))
        elif merged and hs < 5.3:
            expected.append((2, _crossings(hs, to, PEAK_N)[0], "right", "two_feet"))
        elif not merged:
            if abs(hs - 8.55) < 1e-9:  # the right heel is missing at the start probe: foot unknown
                expected.append((2, _crossings(hs, to, PEAK_N)[0], "", "heel_missing"))
            else:
                expected.append((plate, _crossings(hs, to, PEAK_N)[0], side, "ok"))
    # the hand load: the left heel is up in swing over plate 1, the right one stands on plate 2
    expected.append((1, _crossings(*HAND)[0], "", "no_foot"))
    expected.sort(key=lambda e: (e[1], e[0]))
    assert len(judged) == len(expected) == 20
    for r, (plate, start, side, flag) in zip(judged.itertuples(), expected):
        assert (r.plate, r.side, r.flag) == (plate, side, flag)
        assert abs(r.start_s - start) < 0.005
    ok = judged[judged["flag"] == "ok"]
    assert len(ok) == 15 and (ok["side"] == np.where(ok["plate"] == 1, "left", "right")).all()


def test_clean_contacts_give_events_at_the_crossings_and_flagged_ones_none(judged):
    ev = contact_events(judged)
    assert list(ev.columns) == list(EVENT_COLUMNS)
    gait = ev[ev["event"].isin(["heel_strike", "toe_off"])]
    assert len(gait) == 30  # 15 clean contacts
    truth = {}
    for side, _plate, hs, to in _steps():
        a, b = _crossings(hs, to, PEAK_N)
        truth[(side, "heel_strike", round(hs, 2))] = a
        truth[(side, "toe_off", round(hs, 2))] = b
    errors = []
    for r in gait.itertuples():
        # the step this event belongs to: the nearest analytic crossing of that side and kind
        cand = {k: v for k, v in truth.items() if k[0] == r.side and k[1] == r.event}
        key = min(cand, key=lambda k: abs(cand[k] - r.time_s))
        errors.append(abs(cand[key] - r.time_s))
        assert r.time_s == pytest.approx(r.sample / FS, abs=1e-12)
    assert max(errors) < 0.005  # measured: at most 1.2 ms
    # no event at the flagged contacts: the crossover step (left 5.8 s), the right steps 5.25, 6.35 and 8.55 s
    for side, hs in (("left", 5.8), ("right", 5.25), ("right", 6.35), ("right", 8.55)):
        near = gait[(gait["side"] == side) & ((gait["time_s"] - hs).abs() < 0.1)]
        assert near.empty
    # flagged contacts are counted: the hand load, the merged contact, the missing heel (both sides each)
    # and the right side's two incomplete contacts
    assert flagged_contacts(ev) == 5
    assert flagged_contacts(ev, "left") == 3 and flagged_contacts(ev, "right") == 5


def test_strides_leave_out_those_whose_swing_spans_a_flagged_contact(judged):
    ev = contact_events(judged)
    gait_only = ev[ev["event"].isin(["heel_strike", "toe_off"])]

    def hs(t0):  # analytic heel strike (on-threshold crossing) of the step starting at t0
        return _crossings(t0, t0 + STANCE_S, PEAK_N)[0]

    left, right = strides_from_events(ev, "left"), strides_from_events(ev, "right")
    # left steps start at 0.3 + 1.1 k; kept: 0.3, 2.5, 3.6, 6.9, 9.1 s. Left out: 1.4 s (the hand load in its
    # swing), 4.7 -> 6.9 s (the crossover step 5.8 s hides in the merged contact), 8.0 s (the contact with the
    # missing heel may hide the left foot)
    np.testing.assert_allclose(left["heel_strike_s"], [hs(t) for t in (0.3, 2.5, 3.6, 6.9, 9.1)], atol=0.005)
    np.testing.assert_allclose(left["end_s"], [hs(t) for t in (1.4, 3.6, 4.7, 8.0, 10.2)], atol=0.005)
    # right steps start at 0.85 + 1.1 k; kept: 0.85, 1.95, 3.05 s; left out: 4.15 -> 7.45 s (5.25 and 6.35 s
    # hidden) and 7.45 -> 9.65 s (8.55 s flagged). The hand load in the right stance at 2.2 s leaves 1.95 s in.
    np.testing.assert_allclose(right["heel_strike_s"], [hs(t) for t in (0.85, 1.95, 3.05)], atol=0.005)
    np.testing.assert_allclose(right["end_s"], [hs(t) for t in (1.95, 3.05, 4.15)], atol=0.005)
    # without the flagged spans the toe-off rule alone would keep the strides that hide a step
    for side, start, end in (("left", 4.7, 6.9), ("right", 4.15, 7.45), ("right", 7.45, 9.65)):
        plain = strides_from_events(gait_only, side)
        hit = plain[(plain["heel_strike_s"] - hs(start)).abs() < 0.005]
        assert len(hit) == 1 and abs(hit["end_s"].iloc[0] - hs(end)) < 0.005
    # gait_events tables (no flagged rows) are not affected: same strides as before
    t = np.arange(int(4.0 * FS)) / FS
    f = sum(_hump(t, a, a + STANCE_S, PEAK_N) for a in (0.3, 1.4, 2.5))
    ev_belt = gait_events(t, f, "left")
    assert len(strides_from_events(ev_belt, "left")) == 2
    with pytest.raises(LoperInputError, match="do not pair up"):
        strides_from_events(
            ev.drop(index=ev.index[(ev["event"] == "flagged_end") & (ev["side"] == "left")][:1]), "left"
        )


def test_belt_map_is_only_a_check(trial, judged):
    t, raw, tm, heels, _ = trial
    plates = _plates(t, raw)
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
    f = {1: _hump(t, 0.3, 1.0, PEAK_N), 2: _hump(t, 1.6, 2.3, PEAK_N)}
    heels = {"left": _heel("left", steps, tm), "right": np.tile([0.0, -0.5, 0.05], (tm.size, 1))}
    plates = [PlateForce(p, t, f[p], CORNERS[p]) for p in (1, 2)]
    free = foot_contacts(plates, tm, heels)
    assert free[["plate", "side", "flag"]].values.tolist() == [[1, "left", "ok"], [2, "left", "ok"]]
    mapped = foot_contacts(plates, tm, heels, plate_sides={"left": 1, "right": 2})
    assert mapped["flag"].tolist() == ["ok", "wrong_belt"]
    ev = contact_events(mapped)
    assert ev["event"].tolist() == ["heel_strike", "toe_off", "flagged_start", "flagged_end"]
    assert (ev["side"] == "left").all()


WALKING5 = __import__("pathlib").Path(__file__).parents[1] / "data" / "opensim-core" / "walking5.c3d"


@pytest.fixture(scope="module")
def walking5():
    """Plates (force above the resting level, corners in m) and heel markers (m) of walking5.c3d, read with ezc3d."""
    ezc3d = pytest.importorskip("ezc3d")
    c = ezc3d.c3d(str(WALKING5), extract_forceplat_data=True)
    labels = c["parameters"]["POINT"]["LABELS"]["value"]
    points = c["data"]["points"]  # (4, n_markers, n_frames), mm
    rate = float(c["parameters"]["POINT"]["RATE"]["value"][0])
    tm = np.arange(points.shape[2]) / rate
    heels = {"left": points[:3, labels.index("LCAL")].T / 1000.0, "right": points[:3, labels.index("RCAL")].T / 1000.0}
    plates, rest = [], []
    for k, p in enumerate(c["data"]["platform"]):
        fz = p["force"][2]  # N, positive up when loaded
        t = np.arange(fz.size) / float(c["parameters"]["ANALOG"]["RATE"]["value"][0])
        rest.append(float(np.median(fz[t < 1.5])))  # nobody on the plates before 1.9 s
        plates.append(PlateForce(k + 1, t, fz - rest[-1], p["corners"].T / 1000.0))
    return plates, tm, heels, rest


def _crossing_times(t, f):
    """Where the force of one stance rises through ON_N and falls through OFF_N, linear between samples."""
    j = int(np.argmax(f))
    i = int(np.flatnonzero(f[:j] < ON_N)[-1])
    k = j + int(np.flatnonzero(f[j:] <= OFF_N)[0])
    up = t[i] + (ON_N - f[i]) / (f[i + 1] - f[i]) * (t[i + 1] - t[i])
    down = t[k - 1] + (f[k - 1] - OFF_N) / (f[k - 1] - f[k]) * (t[k] - t[k - 1])
    return up, down


def test_walking5_contacts_feet_and_events(walking5):
    plates, tm, heels, rest = walking5
    np.testing.assert_allclose(rest, [-14.0, -17.9], atol=0.5)  # the unloaded plates are not zeroed
    found = foot_contacts(plates, tm, heels, source="walking5")
    assert found["plate"].tolist() == [1, 2]
    # Known answer from the heel markers: the left heel (LCAL) came down at about 1.88 s at x = 1.33 m, behind
    # plate 1 (x 0.665 .. 1.173 m): the plate loaded only at 1.965 s, under the forefoot, with the heel
    # 0.135 m off its edge -> off_plate, left, no event. The right heel (RCAL) landed on plate 2 (x 0 .. 0.610 m)
    # at x = 0.52 m -> ok, right.
    frame = round(1.88 * 250)
    assert heels["left"][frame, 2] < 0.055 and heels["left"][frame, 0] > 1.30
    p1, p2 = found.iloc[0], found.iloc[1]
    assert (p1["side"], p1["flag"]) == ("left", "off_plate")
    assert p1["left_heel_outside_m"] == pytest.approx(0.135, abs=0.002)
    assert p1["left_heel_height_m"] == pytest.approx(0.063, abs=0.002)
    assert (p2["side"], p2["flag"]) == ("right", "ok")
    assert p2["right_heel_outside_m"] == 0.0 and p2["right_heel_height_m"] == pytest.approx(0.053, abs=0.002)
    # contact times are the threshold crossings of the offset-corrected force, within one sample (0.5 ms)
    for row, plate in zip((p1, p2), plates):
        up, down = _crossing_times(plate.time_s, plate.vertical_force_n)
        assert 0.0 <= row["start_s"] - up < 0.0005 and 0.0 <= row["end_s"] - down < 0.0005
    np.testing.assert_allclose(
        [p1["start_s"], p1["end_s"], p2["start_s"], p2["end_s"]], [1.9650, 2.4780, 2.3835, 2.9770], atol=1e-9
    )
    ev = contact_events(found)
    assert ev[["side", "event"]].values.tolist() == [
        ["left", "flagged_start"],
        ["right", "heel_strike"],
        ["left", "flagged_end"],
        ["right", "toe_off"],
    ]
    gait = ev[ev["event"].isin(["heel_strike", "toe_off"])]
    np.testing.assert_allclose(gait["time_s"], [p2["start_s"], p2["end_s"]], atol=0)
    assert gait["sample"].tolist() == [4767, 5954]
    # with a shorter reach no heel explains plate 1 any more
    assert foot_contacts(plates, tm, heels, reach_m=0.10)["flag"].tolist() == ["no_foot", "ok"]


def test_count_flagged_leaves_out_contacts_cut_by_the_recording():
    from loper_analysis.gait.contacts import count_flagged

    assert count_flagged(["ok", "incomplete", "two_feet", "no_foot", "ok", "wrong_belt"]) == 3
    assert count_flagged(pd.Series([], dtype=object)) == 0


def test_plates_in_a_y_up_frame_with_corners_either_way_round_give_the_same_contacts(trial, judged):
    """Corners and heels turned into a Y-up frame ((x, y, z) -> (x, z, -y)), the corners listed the other way
    round, with up = +Y: every contact, foot, flag and heel distance as in the Z-up frame."""
    t, raw, tm, heels, _ = trial
    Q = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])
    plates = [PlateForce(p.plate, p.time_s, p.vertical_force_n, (p.corners_m @ Q.T)[::-1]) for p in _plates(t, raw)]
    turned = foot_contacts(
        plates, tm, {s: h @ Q.T for s, h in heels.items()}, **SETTINGS, source="S01/walk", up=(0.0, 1.0, 0.0)
    )
    pd.testing.assert_frame_equal(
        turned.drop(columns=[c for c in CONTACT_COLUMNS if c.endswith("_m")]),
        judged.drop(columns=[c for c in CONTACT_COLUMNS if c.endswith("_m")]),
    )
    heel = [c for c in CONTACT_COLUMNS if c.endswith("_m")]
    np.testing.assert_allclose(turned[heel].to_numpy(float), judged[heel].to_numpy(float), atol=1e-12)


def test_plate_offsets_with_up_either_corner_order_and_a_tilted_plate_refused():
    c = CORNERS[2]
    points = [[0.2, 0.5, 0.07], [0.6, 0.5, 0.0], [0.7, 1.9, 0.1]]
    for corners in (c, c[::-1]):
        out, height = plate_offsets(points, corners, up=(0.0, 0.0, 1.0))
        np.testing.assert_allclose(out, [0.0, 0.1, math.hypot(0.2, 0.3)], atol=1e-12)
        np.testing.assert_allclose(height, [0.07, 0.0, 0.1], atol=1e-12)
    # up along the plate's own plane: 90 deg from its normal, refused naming the plate
    refusal = (
        r"walk: plate 2: the plate does not face up: surface normal \[0\.0, 0\.0, 1\.0\] is 90\.0 deg from the "
        r"up direction \[0\.0, 1\.0, 0\.0\]"
    )
    with pytest.raises(LoperInputError, match=refusal):
        foot_contacts(
            [PlateForce(2, np.arange(10) / 100.0, np.zeros(10), c)],
            np.arange(2) / 100.0,
            {"left": np.zeros((2, 3)), "right": np.zeros((2, 3))},
            source="walk",
            up=(0.0, 1.0, 0.0),
        )


SYD = __import__("pathlib").Path(__file__).parents[1] / "data" / "c3d-parser" / "SYD" / "walk-nodevice.c3d"


@pytest.fixture(scope="module")
def syd():
    """SYD's plates (force above the resting level, corners in m), heel and toe markers (m), read with ezc3d, and
    each plate's own loaded period: its first sample >= 50 N above its resting level to the sample after its
    last one."""
    ezc3d = pytest.importorskip("ezc3d")
    c = ezc3d.c3d(str(SYD), extract_forceplat_data=True)
    prm = c["parameters"]
    labels = [s.strip() for s in prm["POINT"]["LABELS"]["value"]]
    rate, arate = float(prm["POINT"]["RATE"]["value"][0]), float(prm["ANALOG"]["RATE"]["value"][0])
    t0 = c["header"]["points"]["first_frame"] / rate
    points = c["data"]["points"][:3] / 1000.0  # mm -> m
    points[:, np.all(points == 0.0, axis=0)] = np.nan
    tm = t0 + np.arange(points.shape[2]) / rate
    feet = {m: points[:, labels.index(m)].T for m in ("LHEE", "RHEE", "LTOE", "RTOE")}
    plates, loaded = [], {}
    for k, p in enumerate(c["data"]["platform"], start=1):
        fz = np.asarray(p["force"][2], dtype=float)
        t = t0 + np.arange(fz.size) / arate
        rest = float(np.median(fz[np.argsort(np.abs(fz))[: fz.size // 10]]))  # the tenth of samples nearest zero
        f = fz - rest
        plates.append(PlateForce(k, t, f, np.asarray(p["corners"], dtype=float).T / 1000.0))
        on = np.flatnonzero(f >= ON_N)  # each plate is loaded once in this walk
        loaded[k] = (t[on[0]], t[on[-1] + 1])
    heels = {"left": feet["LHEE"], "right": feet["RHEE"]}
    toes = {"left": feet["LTOE"], "right": feet["RTOE"]}
    return plates, tm, heels, toes, loaded


def test_syd_left_foot_across_two_plates_is_one_contact_from_plate_2_loading_to_plate_1_unloading(syd):
    """The left heel lands on plate 2 and the toes on plate 1 (the heel 58 mm behind plate 1's edge): one foot
    contact, heel strike where plate 2 loads, toe-off where plate 1 unloads (not where plate 2 does, 233 ms early)."""
    plates, tm, heels, toes, loaded = syd
    (p1_on, p1_off), (p2_on, p2_off) = loaded[1], loaded[2]
    np.testing.assert_allclose([p2_on, p2_off, p1_on, p1_off], [2.323, 2.700, 2.374, 2.946], atol=0.001)
    found = foot_contacts(plates, tm, heels, toes_m=toes, source="SYD")
    assert found[["plate", "side", "flag"]].values.tolist() == [
        [3, "right", "ok"],
        [2, "left", "ok"],
        [1, "left", "ok"],
    ]
    assert found["foot_contact"].tolist() == [0, 1, 1]
    assert found["left_heel_outside_m"].iloc[2] == pytest.approx(0.058, abs=0.002)  # behind plate 1, on plate 2
    ev = contact_events(found)
    left = ev[ev["side"] == "left"].set_index("event")["time_s"]
    assert left.index.tolist() == ["heel_strike", "toe_off"]
    assert abs(left["heel_strike"] - p2_on) <= 0.015 and abs(left["toe_off"] - p1_off) <= 0.015
    np.testing.assert_allclose([left["heel_strike"], left["toe_off"]], [2.323, 2.956], atol=1e-9)
    right = ev[ev["side"] == "right"].set_index("event")["time_s"]
    assert abs(right["heel_strike"] - loaded[3][0]) <= 0.015 and abs(right["toe_off"] - loaded[3][1]) <= 0.015


def test_syd_without_toe_markers_the_plate_under_the_toes_is_dropped_with_its_reason_in_the_log(syd, caplog):
    plates, tm, heels, _, _ = syd
    with caplog.at_level("WARNING", logger="loper_analysis.gait.contacts"):
        found = foot_contacts(plates, tm, heels, source="SYD")
    p1 = found[found["plate"] == 1].iloc[0]
    assert (p1["side"], p1["flag"]) == ("", "no_foot")
    assert (
        p1["reason"].startswith("no foot found: no heel on the plate at 2.424 s")
        and "left heel on plate 2" in p1["reason"]
    )
    said = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert said == [
        f"SYD: plate 1 contact 2.374-2.956 s (unknown foot) left out of the events, no_foot: {p1['reason']}"
    ]
    # the left foot's events are then plate 2's alone: its toe-off where plate 2 unloads, 233 ms early
    ev = contact_events(found)
    assert ev.loc[(ev["side"] == "left") & (ev["event"] == "toe_off"), "time_s"].tolist() == [2.723]
