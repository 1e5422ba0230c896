"""Device figures: the Bode plot marks our and the study's bandwidth; the step figure draws one response per
amplitude."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure

from loper_analysis.reference import STUDY_DEVICE
from loper_analysis.report.figures import pyplot
from loper_analysis.report.figures.device import bode_figure, steps_figure


@pytest.fixture
def frf():
    f = np.arange(1, 1001) * 0.2  # 0.2 .. 200 Hz
    h = 1.0 / (1.0 + 1j * f / 40.0)
    return pd.DataFrame(
        {"frequency_hz": f, "gain": np.abs(h), "phase_deg": np.degrees(np.angle(h)), "coherence": np.ones(f.size)}
    )


@pytest.fixture
def average():
    t = np.arange(-50, 300) / 1000.0
    frames = [
        pd.DataFrame(
            {
                "amplitude_n": a,
                "time_s": t,
                "desired_n": np.where(t >= 0, a, 0.0),
                "measured_n": np.where(t >= 0, 0.9 * a, 0.0),
                "measured_sd_n": 1.0,
            }
        )
        for a in (20.0, 40.0, 60.0)
    ]
    return pd.concat(frames, ignore_index=True)


def test_bode_figure_marks_both_bandwidths_and_stops_at_100_hz(frf):
    fig = bode_figure(frf, 38.5)
    try:
        assert isinstance(fig, Figure) and len(fig.axes) == 3
        gain_ax = fig.axes[0]
        verticals = sorted(line.get_xdata()[0] for line in gain_ax.get_lines() if np.ptp(line.get_xdata()) == 0)
        assert verticals == [38.5, STUDY_DEVICE["bandwidth_hz"][0]]
        curve = gain_ax.get_lines()[0]
        assert np.max(curve.get_xdata()) <= 100.0
        np.testing.assert_allclose(curve.get_ydata(), 20 * np.log10(frf.gain[frf.frequency_hz <= 100]))
    finally:
        pyplot().close(fig)


def test_steps_figure_draws_each_amplitude_with_its_target(average):
    fig = steps_figure(average)
    try:
        assert isinstance(fig, Figure)
        ax = fig.axes[0]
        labels = [line.get_label() for line in ax.get_lines() if not line.get_label().startswith("_")]
        assert labels == ["20 N", "40 N", "60 N"]
        targets = sorted(line.get_ydata()[0] for line in ax.get_lines() if np.ptp(line.get_ydata()) == 0)
        assert targets == [20.0, 40.0, 60.0]
    finally:
        pyplot().close(fig)
