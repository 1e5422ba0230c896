"""Joint angles over the gait cycle: each side cut at its own heel strikes."""

from __future__ import annotations

import numpy as np
import pandas as pd

from loper_analysis.report.figures import pyplot
from loper_analysis.report.figures.gait import cycle_angles, ground_reaction_figure, stride_angles_figure


def _trial():
    """Two sides walking 1 s strides, the right half a stride later; each angle a cosine of its stride's phase."""
    t = np.arange(0, 5.0, 0.01)
    rows = []
    for side, shift in (("left", 0.3), ("right", 0.8)):
        for k in range(4):
            rows += [(side, "heel_strike", shift + k), (side, "toe_off", shift + k + 0.6)]
    events = pd.DataFrame(rows, columns=["side", "event", "time_s"]).sort_values("time_s", ignore_index=True)
    angles = {"time_s": t}
    for side, shift in (("left", 0.3), ("right", 0.8)):
        for j, amp in (("hip", 0.4), ("knee", 1.0), ("ankle", 0.2)):
            angles[f"{j}_{side}_rad"] = amp * np.cos(2 * np.pi * (t - shift))
    return pd.DataFrame(angles), events


def test_each_side_is_cut_at_its_own_heel_strikes_and_normalised():
    angles, events = _trial()
    for side in ("left", "right"):
        cycles = cycle_angles(angles, events, side)
        assert cycles.shape == (3, 101, 3)  # three complete strides per side
        expected = np.cos(2 * np.pi * np.linspace(0, 1, 101))
        np.testing.assert_allclose(cycles[:, :, 1], np.tile(expected, (3, 1)), atol=5e-4)  # knee, amplitude 1
        np.testing.assert_allclose(cycles[:, :, 0], 0.4 * np.tile(expected, (3, 1)), atol=2e-4)


def test_a_stride_over_missing_samples_or_beyond_the_table_is_left_out():
    angles, events = _trial()
    angles.loc[(angles.time_s > 1.5) & (angles.time_s < 1.6), "knee_left_rad"] = np.nan
    assert len(cycle_angles(angles, events, "left")) == 2
    assert len(cycle_angles(angles[angles.time_s < 2.5], events, "right")) == 1  # 0.8 .. 1.8 s only


def test_the_figures_draw_with_and_without_the_lab_s_angles():
    angles, events = _trial()
    plt = pyplot()
    fig = stride_angles_figure(angles, events, angles.assign(knee_left_rad=angles.knee_left_rad + 0.05))
    assert len(fig.axes) == 6 and fig.axes[2].get_legend() is None
    assert [line.get_label() for line in fig.axes[0].get_lines()] == ["ours (3 strides)", "lab's own"]
    plt.close(fig)
    grf = pd.DataFrame({"time_s": angles.time_s, "1_ground_force_vy": 700.0, "2_ground_force_vy": 0.0})
    fig = ground_reaction_figure(grf, events)
    assert len(fig.axes[0].get_lines()) == 2 + len(events)
    plt.close(fig)
