"""The cycle table of two strides (gait.cycles) against its hand-computed rows."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.gait.cycles import cycles_table

T = np.arange(0.0, 4.0, 0.001)
STRIDES = pd.DataFrame({"stride": [3, 7], "heel_strike_s": [1.0, 2.2], "toe_off_s": [1.6, 2.9], "end_s": [2.2, 3.4]})
SOURCES = {"angles": "S01 walk angles", "force": "S01 walk force"}


def _angles(t: np.ndarray) -> np.ndarray:
    return np.column_stack([2.0 * t, 1.0 - t])


def test_two_strides_give_their_hand_computed_rows():
    """Each phase's three samples fall at the hand-computed times of a linear angle and force."""
    table = cycles_table(T, _angles(T), ["hip", "knee"], STRIDES, 3, 100.0 * T, SOURCES)
    assert list(table.columns) == ["stride", "phase", "point", "percent", "hip", "knee", "force_n"]
    assert len(table) == 3 * 2 * 3
    times = {
        "stride": [1.0, 1.6, 2.2, 2.2, 2.8, 3.4],
        "stance": [1.0, 1.3, 1.6, 2.2, 2.55, 2.9],
        "swing": [1.6, 1.9, 2.2, 2.9, 3.15, 3.4],
    }
    assert list(table["phase"]) == ["stride"] * 6 + ["stance"] * 6 + ["swing"] * 6
    for phase, t in times.items():
        rows = table[table["phase"] == phase]
        assert list(rows["stride"]) == [3, 3, 3, 7, 7, 7]
        assert list(rows["point"]) == [0, 1, 2, 0, 1, 2]
        assert list(rows["percent"]) == [0.0, 50.0, 100.0, 0.0, 50.0, 100.0]
        np.testing.assert_allclose(rows["hip"], 2.0 * np.array(t), rtol=0, atol=1e-9)
        np.testing.assert_allclose(rows["knee"], 1.0 - np.array(t), rtol=0, atol=1e-9)
        np.testing.assert_allclose(rows["force_n"], 100.0 * np.array(t), rtol=0, atol=1e-7)


def test_without_force_there_is_no_force_column():
    """No force: the angle columns end the table and the values equal those with a force."""
    with_force = cycles_table(T, _angles(T), ["hip", "knee"], STRIDES, 5, 100.0 * T, SOURCES)
    table = cycles_table(T, _angles(T), ["hip", "knee"], STRIDES, 5, None, SOURCES)
    assert list(table.columns) == ["stride", "phase", "point", "percent", "hip", "knee"]
    pd.testing.assert_frame_equal(table, with_force.drop(columns="force_n"))


def test_a_gap_names_the_angles_or_the_force():
    """A NaN inside a stride is reported under the name of the signal that holds it."""
    angles = _angles(T)
    angles[1500, 1] = np.nan  # t = 1.5 s, inside stride 3
    with pytest.raises(LoperInputError, match=r"^S01 walk angles: values are not finite at sample 1500 \(t = 1.5 s\)"):
        cycles_table(T, angles, ["hip", "knee"], STRIDES, 3, 100.0 * T, SOURCES)
    force = 100.0 * T
    force[3000] = np.nan  # t = 3.0 s, inside stride 7
    with pytest.raises(LoperInputError, match=r"^S01 walk force: values are not finite at sample 3000 \(t = 3.0 s\)"):
        cycles_table(T, _angles(T), ["hip", "knee"], STRIDES, 3, force, SOURCES)
