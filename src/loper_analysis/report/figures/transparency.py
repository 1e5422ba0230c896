"""The transparency figure: interaction force and joint angles over the gait cycle, with and without the device."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.report.figures import closed_on_error, pyplot
from loper_analysis.study_design import TRANSPARENCY_CONDITIONS
from loper_analysis.transparency import strides_array

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["transparency_figure"]


def transparency_figure(
    angles_rad: Mapping[str, np.ndarray],
    force_n=None,
    toe_off_pct: float | Mapping[str, float] | None = None,
    joints: Sequence[str] = JOINTS,
    title: str | None = None,
) -> Figure:
    """The transparency figure: interaction force and joint angles over the gait cycle.

    Panels top to bottom: interaction force (device only), then one panel per
    joint; each curve is the mean across strides with ±1 SD shaded, against
    0-100 % of the stride. Angles are drawn in degrees (converted here).
    Dashed vertical lines mark the mean toe-off of each condition.

    Parameters
    ----------
    angles_rad : mapping
        ``{"no_device" | "device": array (n_strides >= 2, n_points, n_joints)}``,
        stride-normalised joint angles in rad (either condition may be absent;
        with neither, the figure says that no subject had enough strides).
    force_n : array_like, shape (n_strides >= 2, n_points), optional
        Stride-normalised interaction force in N (device condition).
    toe_off_pct : float or mapping, optional
        Mean toe-off in % of the stride (:func:`mean_toe_off_pct`), one value
        or one per condition.
    joints : sequence of str
        Names of the joint axis.
    title : str, optional
        Figure title.

    Returns
    -------
    matplotlib.figure.Figure
    """
    conditions = [c for c in TRANSPARENCY_CONDITIONS if c in angles_rad]
    if set(angles_rad) - set(TRANSPARENCY_CONDITIONS):
        raise LoperInputError(
            f"angles_rad must map some of {TRANSPARENCY_CONDITIONS} to arrays, got {sorted(angles_rad)}"
        )
    if not conditions:
        return _no_strides_figure(title)
    joints = [str(j) for j in joints]
    data = _condition_angles(angles_rad, conditions, len(joints))
    force = None if force_n is None else strides_array("force_n", force_n)
    if force is not None and force.ndim != 2:
        raise LoperInputError(f"force_n must have shape (n_strides, n_points), got {force.shape}")
    toe_off = _toe_off_by_condition(toe_off_pct, conditions)
    plt = pyplot()
    colors = {"no_device": "0.35", "device": "tab:blue"}
    labels = {"no_device": "without device", "device": "with device"}
    n_panels = len(joints) + (force is not None)
    fig, axes = plt.subplots(
        n_panels, 1, figsize=(5.5, 2.0 * n_panels + 0.6), sharex=True, constrained_layout=True, squeeze=False
    )
    axes = axes[:, 0]

    with closed_on_error(fig):
        panel = 0
        if force is not None:
            _band(axes[0], force, colors["device"], f"{labels['device']} (n = {force.shape[0]})")
            axes[0].axhline(0, color="0.6", lw=0.8)
            axes[0].set_ylabel("interaction force (N)")
            panel = 1
        for j, joint in enumerate(joints):
            ax = axes[panel + j]
            for c in conditions:
                _band(ax, np.degrees(data[c][:, :, j]), colors[c], f"{labels[c]} (n = {data[c].shape[0]})")
            ax.set_ylabel(f"{joint} angle (deg)")
        for ax in axes:
            for c, pct in toe_off.items():
                ax.axvline(pct, color=colors[c], ls="--", lw=1)
        axes[panel].legend(frameon=False, fontsize=8)
        if force is not None:
            axes[0].legend(frameon=False, fontsize=8)
        axes[-1].set_xlim(0, 100)
        axes[-1].set_xlabel("gait cycle (%)  -  dashed: mean toe-off")
        if title:
            fig.suptitle(title)
    return fig


def _no_strides_figure(title: str | None) -> Figure:
    """A small figure saying that no subject had enough kept strides in both conditions."""
    fig = pyplot().figure(figsize=(5.5, 2.0))
    ax = fig.add_subplot()
    ax.text(
        0.5,
        0.5,
        "no subject with enough kept strides in both conditions",
        transform=ax.transAxes,
        ha="center",
        va="center",
        color="0.4",
        fontsize=11,
    )
    ax.set_axis_off()
    if title:
        fig.suptitle(title)
    return fig


def _condition_angles(
    angles_rad: Mapping[str, np.ndarray], conditions: Sequence[str], n_joints: int
) -> dict[str, np.ndarray]:
    """Each condition's stride-normalised angles (rad, shape (n_strides >= 2, n_points, n_joints)), checked."""
    data = {}
    for c in conditions:
        x = strides_array(f"angles_rad[{c!r}]", angles_rad[c])
        if x.ndim != 3 or x.shape[2] != n_joints:
            raise LoperInputError(f"angles_rad[{c!r}] must have shape (n_strides, n_points, {n_joints}), got {x.shape}")
        data[c] = x
    return data


def _toe_off_by_condition(
    toe_off_pct: float | Mapping[str, float] | None, conditions: Sequence[str]
) -> dict[str, float]:
    """The mean toe-off (% of the stride) of each drawn condition: one value for all, one per condition, or
    none."""
    if isinstance(toe_off_pct, Mapping):
        return {c: float(v) for c, v in toe_off_pct.items() if c in conditions}
    if toe_off_pct is not None:
        return {c: float(toe_off_pct) for c in conditions}
    return {}


def _band(ax, x: np.ndarray, color: str, label: str) -> None:
    """Draw the mean across strides of ``x`` (n_strides, n_points) with ±1 SD shaded, against 0-100 % of the
    stride."""
    m, s = x.mean(axis=0), x.std(axis=0, ddof=1)
    pct = np.linspace(0.0, 100.0, m.size)
    ax.plot(pct, m, color=color, lw=1.5, label=label)
    ax.fill_between(pct, m - s, m + s, color=color, alpha=0.25, lw=0)
