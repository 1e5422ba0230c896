"""Figures of a recorded trial's quality: joint angles over the gait cycle, and ground reactions with the events.

* :func:`cycle_angles` - each side's joint angles cut at its heel strikes and time-normalised;
* :func:`stride_angles_figure` - hip, knee and ankle of both sides over the gait cycle, mean ± SD over the
  strides, the lab's own angles (where the file holds them) beside ours;
* :func:`ground_reaction_figure` - the vertical force of each force plate over the trial, with the heel
  strikes and toe-offs found.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from loper_analysis.constants import JOINTS, SIDES
from loper_analysis.gait.resampling import cut
from loper_analysis.gait.strides import strides_from_events
from loper_analysis.report.figures import closed_on_error, pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["cycle_angles", "ground_reaction_figure", "stride_angles_figure"]

#: Points per normalised stride (0 .. 100 %).
_N_POINTS = 101
_SIDE_COLOUR = {"left": "tab:red", "right": "tab:blue"}
#: Plate colours: none of the sides' colours.
_PLATE_COLOURS = ("0.35", "tab:green", "tab:purple", "tab:orange", "tab:brown", "tab:olive", "tab:cyan", "tab:pink")


def cycle_angles(angles: pd.DataFrame, events: pd.DataFrame, side: str, n_points: int = _N_POINTS) -> np.ndarray:
    """One side's hip, knee and ankle angles over its strides (heel strike to heel strike), time-normalised.

    Parameters
    ----------
    angles : pandas.DataFrame
        ``time_s`` and ``{joint}_{side}_rad`` (ours or the lab's; a joint it lacks is NaN).
    events : pandas.DataFrame
        The trial's events (``side``, ``event``, ``time_s``): :func:`loper_analysis.gait.strides.strides_from_events`.
    side : {"left", "right"}
    n_points : int
        Points per stride.

    Returns
    -------
    numpy.ndarray
        (n_strides, n_points, 3) in rad; strides the table does not cover, or with a missing sample, are left out.
    """
    strides = strides_from_events(events, side) if len(events) else pd.DataFrame()
    t = angles["time_s"].to_numpy(float)
    columns = [f"{j}_{side}_rad" for j in JOINTS]
    values = np.column_stack([angles[c].to_numpy(float) if c in angles else np.full(t.size, np.nan) for c in columns])
    out = []
    for row in strides.itertuples():
        inside = (t >= row.heel_strike_s) & (t <= row.end_s)
        if t.size < 2 or row.heel_strike_s < t[0] or row.end_s > t[-1] or not np.isfinite(values[inside]).all():
            continue
        out.append(cut(t, values, [row.heel_strike_s], [row.end_s], n_points)[0])
    return np.stack(out) if out else np.empty((0, n_points, len(JOINTS)))


def stride_angles_figure(
    angles: pd.DataFrame, events: pd.DataFrame, lab: pd.DataFrame | None = None, title: str | None = None
) -> Figure:
    """Hip, knee and ankle (rows) of the left and right side (columns) over the gait cycle, in degrees.

    Ours: the mean over the strides, ±1 SD shaded; the lab's own (``lab``, where it holds the joint): the mean,
    dashed. A panel without a complete stride says so.
    """
    plt = pyplot()
    fig, axes = plt.subplots(len(JOINTS), len(SIDES), figsize=(8, 6.5), sharex=True, squeeze=False)
    with closed_on_error(fig):
        pct = np.linspace(0, 100, _N_POINTS)
        for c, side in enumerate(SIDES):
            ours = cycle_angles(angles, events, side)
            theirs = cycle_angles(lab, events, side) if lab is not None and len(lab) else None
            for r, joint in enumerate(JOINTS):
                ax = axes[r, c]
                if len(ours):
                    m, sd = np.degrees(ours[:, :, r].mean(axis=0)), np.degrees(ours[:, :, r].std(axis=0))
                    ax.fill_between(pct, m - sd, m + sd, color=_SIDE_COLOUR[side], alpha=0.2, lw=0)
                    ax.plot(pct, m, color=_SIDE_COLOUR[side], lw=1.5, label=f"ours ({len(ours)} strides)")
                else:
                    ax.text(0.5, 0.5, "no complete stride", ha="center", va="center", transform=ax.transAxes)
                    ax.set_yticks([])
                if theirs is not None and len(theirs) and np.isfinite(theirs[:, :, r]).all():
                    ax.plot(pct, np.degrees(theirs[:, :, r].mean(axis=0)), "k--", lw=1, label="lab's own")
                ax.set_title(f"{joint} {side}", fontsize=9)
                if c == 0:
                    ax.set_ylabel("deg")
                if r == len(JOINTS) - 1:
                    ax.set_xlabel("% of the stride (heel strike to heel strike)")
                if r == 0 and ax.get_legend_handles_labels()[0]:
                    ax.legend(fontsize=7, loc="best")
        fig.suptitle(title or "joint angles over the gait cycle: flexion and dorsiflexion positive", fontsize=10)
        fig.tight_layout()
    return fig


def ground_reaction_figure(grf: pd.DataFrame, events: pd.DataFrame, title: str | None = None) -> Figure:
    """The vertical force of each plate (``{n}_ground_force_vy`` of an external-loads table, N) over time, with
    the heel strikes (solid) and toe-offs (dotted) of each side."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.2))
    with closed_on_error(fig):
        t = grf["time"].to_numpy(float) if "time" in grf else grf["time_s"].to_numpy(float)
        plates = [c for c in grf.columns if c.endswith("_ground_force_vy")]
        for k, c in enumerate(plates):
            colour = _PLATE_COLOURS[k % len(_PLATE_COLOURS)]
            ax.plot(t, grf[c].to_numpy(float), lw=1, color=colour, label=f"plate {c.split('_')[0]}")
        for row in events.itertuples():
            if row.event in ("heel_strike", "toe_off"):
                ax.axvline(row.time_s, color=_SIDE_COLOUR.get(row.side, "k"), lw=0.8,
                           ls="-" if row.event == "heel_strike" else ":")  # fmt: skip
        ax.set_xlabel("time (s, the file's clock)")
        ax.set_ylabel("vertical force (N)")
        ax.set_title(title or "force plates; heel strikes solid, toe-offs dotted (left red, right blue)", fontsize=9)
        if plates:
            ax.legend(fontsize=7, loc="upper right")
        fig.tight_layout()
    return fig
