"""A foot across force plates (loper_analysis.gait.foot_across_plates): SYD's left foot with its heel on one plate
and its toes on the next is one foot contact; without toe markers the plate under the toes is dropped, its reason
in the log."""

import numpy as np
import pytest

from loper_analysis.gait.contacts import PlateForce, contact_events, foot_contacts
from tests.gait.belt_walk import ON_N

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
