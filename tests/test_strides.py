"""loper_analysis.strides on frames: interaction-force metrics per phase, the stride tables of a short trial
and the per-trial summary, against known answers."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.strides import force_phase_metrics, stride_summary, stride_tables

FS = 1000.0


def _stride_table():
    # strides of 1 s: stance 0.6 s (3 periods of 5 Hz), swing 0.4 s (2 periods)
    hs = np.array([0.5, 1.5, 2.5])
    return pd.DataFrame({
        "stride": [0, 1, 2], "heel_strike_s": hs, "toe_off_s": hs + 0.6, "end_s": hs + 1.0,
        "stance_s": 0.6, "duration_s": 1.0,
    })


# --------------------------------------------------------------------------- force per phase


def test_force_metrics_of_a_constant_force():
    t = np.arange(0, 4, 1 / FS)
    m = force_phase_metrics(t, np.full(t.size, -3.5), _stride_table())
    assert list(m.columns) == ["stride", "phase", "rms_force_n", "max_abs_force_n"]
    np.testing.assert_array_equal(m["stride"], [0, 0, 1, 1, 2, 2])
    np.testing.assert_array_equal(m["phase"], ["stance", "swing"] * 3)
    np.testing.assert_allclose(m["rms_force_n"], 3.5, rtol=1e-12)
    np.testing.assert_allclose(m["max_abs_force_n"], 3.5, rtol=0)


def test_force_metrics_of_a_sine_have_the_analytic_rms():
    t = np.arange(0, 4, 1 / FS)
    amplitude = 6.0
    # phase starts at 0.5 s, a whole number of 5 Hz periods from 0: integer periods in each phase
    m = force_phase_metrics(t, amplitude * np.sin(2 * np.pi * 5.0 * t), _stride_table())
    np.testing.assert_allclose(m["rms_force_n"], amplitude / np.sqrt(2), rtol=1e-12)
    np.testing.assert_allclose(m["max_abs_force_n"], amplitude, rtol=1e-12)  # 200 samples/period: the peak is a sample
    # a force only in swing: stance is zero
    f = np.where(((t - 0.5) % 1.0) >= 0.6 - 1e-9, 2.0, 0.0)
    m = force_phase_metrics(t, f, _stride_table())
    np.testing.assert_allclose(m.loc[m.phase == "stance", "rms_force_n"], 0.0, atol=0)
    np.testing.assert_allclose(m.loc[m.phase == "swing", "rms_force_n"], 2.0, rtol=1e-12)


def test_force_metrics_bad_inputs_name_the_source():
    t = np.arange(0, 4, 1 / FS)
    f = np.zeros(t.size)
    f[1234] = np.inf
    with pytest.raises(LoperInputError, match="S01/T02: force_n is not finite at sample 1234"):
        force_phase_metrics(t, f, _stride_table(), source="S01/T02")
    with pytest.raises(LoperInputError, match=r"S01/T02: stride 2 swing \(3.1 .. 3.5 s\) is empty or outside"):
        force_phase_metrics(t[:3200], np.zeros(3200), _stride_table(), source="S01/T02")
    with pytest.raises(LoperInputError, match="S01/T02: stride_table lacks column"):
        force_phase_metrics(t, np.zeros(t.size), _stride_table().drop(columns="toe_off_s"), source="S01/T02")


# --------------------------------------------------------------------------- stride tables and summary


def test_fewer_than_five_valid_strides_warn():
    """Five left heel strikes give 4 strides, all kept (enough for the outlier rule), too few for the analysis.

    Every angle is one curve of the stride phase plus a slow drift, so at each normalised sample the 4 strides
    are equally spaced (a, a + d, a + 2d, a + 3d): Q1 = a + 0.75d, Q3 = a + 2.25d, none outside 1.5 IQR.
    """
    t = np.arange(0, 7.0, 1 / 128)
    heel_strikes = 0.5 + 1.2 * np.arange(5)
    phase = 2 * np.pi * (t - 0.5) / 1.2
    angles = pd.DataFrame({"time_s": t, "hip_left_rad": 0.4 * np.sin(phase) + 0.01 * t,
                           "knee_left_rad": 0.6 * np.sin(phase + 1.0) ** 2 + 0.01 * t,
                           "ankle_left_rad": 0.2 * np.cos(phase) - 0.01 * t})
    events = pd.DataFrame({
        "side": "left",
        "event": ["heel_strike", "toe_off"] * 5,
        "time_s": np.column_stack([heel_strikes, heel_strikes + 0.72]).ravel(),
    })
    with pytest.warns(TooFewStridesWarning, match="only 4 valid stride"):
        tables = stride_tables(angles, events, side="left")
    assert len(tables.strides) == 4 and not tables.strides["removed"].any()
    assert tables.too_few_strides


def test_stride_summary_counts_removed_and_kept_strides():
    base = pd.DataFrame({
        "stride": range(8), "duration_s": 1.2, "fraction_outlying_hip": 0.0, "fraction_outlying_knee": 0.0,
        "removed": False, "reason": "", "perturbed": False,
    })
    few = base.copy()
    few.loc[3:, "removed"] = True
    few.loc[3:, "reason"] = "knee: 30.0 % of samples outside 1.5·IQR"
    out = stride_summary({("S99", "walk"): base, ("S99", "few"): few}, min_valid=5)
    ok, flagged = out.iloc[0], out.iloc[1]
    assert ok.status == "ok" and ok.n_strides == 8 and ok.n_kept == 8 and ok.n_perturbed == 0
    assert flagged.status == "too_few_strides" and flagged.n_kept == 3
    assert flagged.n_removed == flagged.n_removed_knee == 5 and flagged.n_removed_hip == 0
    np.testing.assert_allclose(out["mean_stride_s"], 1.2)
