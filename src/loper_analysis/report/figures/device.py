"""Figures of the device tests: the Bode plot of the force controller and its averaged step responses."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from loper_analysis.reference import STUDY_DEVICE
from loper_analysis.report.figures import pyplot

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["bode_figure", "steps_figure"]


def bode_figure(frf: pd.DataFrame, bandwidth_hz: float) -> Figure:
    """Bode plot (gain in dB, phase, coherence) up to 100 Hz with the -3 dB bandwidth, ours and the study's.

    ``frf``: ``frequency_hz``, ``gain`` (N/N), ``phase_deg``, ``coherence``
    (:func:`loper_analysis.device.analysis.frequency_response`);
    ``bandwidth_hz``: ours (Hz). Returns the figure.
    """
    plt = pyplot()
    f = frf["frequency_hz"]
    keep = f <= 100
    study = STUDY_DEVICE["bandwidth_hz"][0]
    fig, axes = plt.subplots(
        3, 1, figsize=(6.5, 7), sharex=True, constrained_layout=True, gridspec_kw={"height_ratios": [3, 2, 1]}
    )
    axes[0].semilogx(f[keep], 20 * np.log10(frf["gain"][keep]), color="k")
    axes[0].axvline(bandwidth_hz, color="tab:blue", ls="--", label=f"bandwidth {bandwidth_hz:.1f} Hz")
    axes[0].axvline(study, color="tab:red", ls=":", label=f"study {study:g} Hz")
    axes[0].axhline(-3, color="0.6", lw=0.8)
    axes[0].set_ylabel("gain F_m/F_d (dB)")
    axes[0].legend(frameon=False)
    axes[1].semilogx(f[keep], frf["phase_deg"][keep], color="k")
    axes[1].set_ylabel("phase (deg)")
    axes[2].semilogx(f[keep], frf["coherence"][keep], color="k")
    axes[2].set_ylim(0, 1.05)
    axes[2].set_ylabel("coherence")
    axes[2].set_xlabel("frequency (Hz)")
    return fig


def steps_figure(average: pd.DataFrame) -> Figure:
    """Averaged step responses per amplitude (mean ± SD, N) against time after the step (ms), with the targets.

    ``average``: ``amplitude_n``, ``time_s``, ``measured_n``, ``measured_sd_n``
    (:func:`loper_analysis.device.analysis.step_averages`). Returns the figure.
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.5, 4), constrained_layout=True)
    for (a, g), color in zip(average.groupby("amplitude_n"), ("tab:blue", "tab:orange", "tab:green", "tab:red")):
        t = 1e3 * g["time_s"]
        ax.plot(t, g["measured_n"], color=color, label=f"{a:.0f} N")
        ax.fill_between(
            t, g["measured_n"] - g["measured_sd_n"], g["measured_n"] + g["measured_sd_n"], color=color, alpha=0.25, lw=0
        )
        ax.axhline(a, color=color, ls="--", lw=0.8)
    ax.set_xlabel("time after step onset (ms)")
    ax.set_ylabel("interaction force (N)")
    ax.legend(frameon=False, title="target")
    return fig
