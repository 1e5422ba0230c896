"""Force-plate contacts and their events (loper_analysis.gait.contacts): bad input named, events and strides of a
split-belt treadmill with known answers, walking5's contacts, plates in a Y-up frame."""

import math

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.contacts import CONTACT_COLUMNS, PlateForce, contact_events, foot_contacts
from loper_analysis.gait.events import EVENT_COLUMNS, flagged_contacts, gait_events
from loper_analysis.gait.plate_geometry import plate_offsets
from loper_analysis.gait.strides import strides_from_events
from tests.gait.belt_walk import (
    CORNERS,
    FS,
    OFF_N,
    ON_N,
    PEAK_N,
    SETTINGS,
    STANCE_S,
    WALK_SEED,
    belt_steps,
    belt_walk,
    crossings,
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


def test_bad_input_is_named(trial):
    t, raw, tm, heels, _ = trial
    plates = plates_above_rest(t, raw)
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


def test_clean_contacts_give_events_at_the_crossings_and_flagged_ones_none(judged):
    ev = contact_events(judged)
    assert list(ev.columns) == list(EVENT_COLUMNS)
    gait = ev[ev["event"].isin(["heel_strike", "toe_off"])]
    assert len(gait) == 30  # 15 clean contacts
    truth = {}
    for side, _plate, hs, to in belt_steps():
        a, b = crossings(hs, to, PEAK_N)
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
        return crossings(t0, t0 + STANCE_S, PEAK_N)[0]

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
    f = sum(hump(t, a, a + STANCE_S, PEAK_N) for a in (0.3, 1.4, 2.5))
    ev_belt = gait_events(t, f, "left")
    assert len(strides_from_events(ev_belt, "left")) == 2
    with pytest.raises(LoperInputError, match="do not pair up"):
        strides_from_events(
            ev.drop(index=ev.index[(ev["event"] == "flagged_end") & (ev["side"] == "left")][:1]), "left"
        )


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
    plates = [
        PlateForce(p.plate, p.time_s, p.vertical_force_n, (p.corners_m @ Q.T)[::-1]) for p in plates_above_rest(t, raw)
    ]
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
