"""The events step on a treadmill C3D written with known belt forces: heel strikes where the force first
reaches 50 N, toe-offs where it first falls to 20 N, each belt's foot confirmed by the lower heel."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.stages.events.step import EventSettings, events

POINT_RATE_HZ, ANALOG_RATE_HZ, DURATION_S = 100.0, 1000.0, 4.5
#: Stances (loading starts, unloading ends), s: three per belt, double support between them.
STANCES = {"left": [(0.2, 0.9), (1.5, 2.2), (2.8, 3.5)], "right": [(0.85, 1.55), (2.15, 2.85), (3.45, 4.15)]}
RAMP_S, LOAD_N = 0.05, 700.0


def _belt_force(t: np.ndarray, stances) -> np.ndarray:
    """0 N in swing, 700 N in stance, with 50 ms linear ramps inside each stance's ends."""
    f = np.zeros_like(t)
    for a, b in stances:
        f = np.maximum(f, LOAD_N * np.clip(np.minimum(t - a, b - t) / RAMP_S, 0.0, 1.0))
    return f


def _heel_height(t: np.ndarray, stances) -> np.ndarray:
    """A heel 5 cm high in its own stance, 15 cm in swing."""
    h = np.full(t.size, 0.15)
    for a, b in stances:
        h[(t >= a) & (t <= b)] = 0.05
    return h


@pytest.fixture
def treadmill(tmp_path):
    ta = np.arange(int(DURATION_S * ANALOG_RATE_HZ)) / ANALOG_RATE_HZ
    tm = np.arange(int(DURATION_S * POINT_RATE_HZ)) / POINT_RATE_HZ
    X = np.zeros((tm.size, 2, 3))
    X[:, 0, :2], X[:, 1, :2] = [0.1, 0.1], [0.1, -0.1]
    X[:, 0, 2], X[:, 1, 2] = _heel_height(tm, STANCES["left"]), _heel_height(tm, STANCES["right"])  # Z up
    forces = np.column_stack([_belt_force(ta, STANCES["left"]), _belt_force(ta, STANCES["right"])])
    return write_c3d(
        tmp_path / "walk.c3d", ["LHEE", "RHEE"], X, POINT_RATE_HZ, ["Fz_left", "Fz_right"], forces, ["N", "N"],
        ANALOG_RATE_HZ,
    )  # fmt: skip


def _expected() -> pd.DataFrame:
    """Heel strike: the force 700 (t - a) / 0.05 first >= 50 N at a + 3.57 ms, the next sample a + 4 ms;
    toe-off: 700 (b - t) / 0.05 first <= 20 N at b - 1.43 ms, the next sample b - 1 ms."""
    rows = []
    for side, stances in STANCES.items():
        for a, b in stances:
            rows.append((side, "heel_strike", round(a * 1000) + 4))
            rows.append((side, "toe_off", round(b * 1000) - 1))
    table = pd.DataFrame(rows, columns=["side", "event", "sample"]).sort_values("sample", ignore_index=True)
    return table.assign(time_s=table["sample"] / ANALOG_RATE_HZ)[["side", "event", "time_s", "sample"]]


def test_events_are_the_first_samples_past_the_two_thresholds(treadmill, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # three stances a belt: both belts' feet confirmed, nothing to warn of
        table = events(treadmill, tmp_path / "events.tsv", contacts_out=tmp_path / "contacts.tsv")
    expected = _expected()
    pd.testing.assert_frame_equal(table.reset_index(drop=True), expected, check_dtype=False)
    written = pd.read_csv(tmp_path / "events.tsv", sep="\t")
    pd.testing.assert_frame_equal(written, expected, check_dtype=False)
    assert len(pd.read_csv(tmp_path / "contacts.tsv", sep="\t")) == 0  # no force platforms: no plate contacts


def test_the_thresholds_come_from_the_settings(treadmill, tmp_path):
    """400 N on: 700 (t - a) / 0.05 >= 400 from a + 28.6 ms (sample a + 29 ms); 300 N off: 700 (b - t) / 0.05 <= 300
    from b - 21.4 ms (sample b - 21 ms)."""
    settings = EventSettings(threshold_on_n=400.0, threshold_off_n=300.0)
    table = events(treadmill, tmp_path / "events.tsv", settings)
    left = table[table["side"] == "left"]
    np.testing.assert_array_equal(left.loc[left["event"] == "heel_strike", "sample"], [229, 1529, 2829])
    np.testing.assert_array_equal(left.loc[left["event"] == "toe_off", "sample"], [879, 2179, 3479])


def test_swapped_belt_channels_are_refused_before_anything_is_written(treadmill, tmp_path):
    swapped = EventSettings(grf_channels={"left": "Fz_right", "right": "Fz_left"})
    with pytest.raises(
        LoperInputError,
        match=r"walk\.c3d: events\.grf_channels\.left: channel Fz_right does not carry the left foot: in 3 of its "
        r"3 stances the right heel \(RHEE\) was the lower at mid-stance \(by 100 mm, median\)",
    ):
        events(treadmill, tmp_path / "events.tsv", swapped)
    assert not (tmp_path / "events.tsv").exists()
