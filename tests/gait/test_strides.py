"""loper_analysis.gait.strides on frames: interaction-force metrics per phase, the stride tables of a short trial
and the per-trial summary, against known answers."""

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError, TooFewStridesWarning
from loper_analysis.gait.strides import force_phase_metrics, stride_summary, stride_tables

FS = 1000.0


def _stride_table():
    # strides of 1 s: stance 0.6 s (3 periods of 5 Hz), swing 0.4 s (2 periods)
    hs = np.array([0.5, 1.5, 2.5])
    return pd.DataFrame(
        {
            "stride": [0, 1, 2],
            "heel_strike_s": hs,
            "toe_off_s": hs + 0.6,
            "end_s": hs + 1.0,
            "stance_s": 0.6,
            "duration_s": 1.0,
        }
    )


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
    angles = pd.DataFrame(
        {
            "time_s": t,
            "hip_left_rad": 0.4 * np.sin(phase) + 0.01 * t,
            "knee_left_rad": 0.6 * np.sin(phase + 1.0) ** 2 + 0.01 * t,
            "ankle_left_rad": 0.2 * np.cos(phase) - 0.01 * t,
        }
    )
    events = pd.DataFrame(
        {
            "side": "left",
            "event": ["heel_strike", "toe_off"] * 5,
            "time_s": np.column_stack([heel_strikes, heel_strikes + 0.72]).ravel(),
        }
    )
    with pytest.warns(TooFewStridesWarning, match="only 4 valid stride"):
        tables = stride_tables(angles, events, side="left")
    assert len(tables.strides) == 4 and not tables.strides["removed"].any()
    assert tables.too_few_strides


def test_stride_summary_counts_removed_and_kept_strides():
    base = pd.DataFrame(
        {
            "stride": range(8),
            "duration_s": 1.2,
            "fraction_outlying_hip": 0.0,
            "fraction_outlying_knee": 0.0,
            "removed": False,
            "reason": "",
            "perturbed": False,
        }
    )
    few = base.copy()
    few.loc[3:, "removed"] = True
    few.loc[3:, "reason"] = "knee: 30.0 % of samples outside 1.5·IQR"
    out = stride_summary({("S99", "walk"): base, ("S99", "few"): few}, min_valid=5)
    ok, flagged = out.iloc[0], out.iloc[1]
    assert ok.status == "ok" and ok.n_strides == 8 and ok.n_kept == 8 and ok.n_perturbed == 0
    assert flagged.status == "too_few_strides" and flagged.n_kept == 3
    assert flagged.n_removed == flagged.n_removed_knee == 5 and flagged.n_removed_hip == 0
    np.testing.assert_allclose(out["mean_stride_s"], 1.2)


# --------------------------------------------------------------------------- trials with 0 or 1 strides

#: Columns of a stride table with a force table, in order (the table of any number of strides, 0 included).
STRIDE_COLUMNS = [
    "stride",
    "side",
    "heel_strike_s",
    "toe_off_s",
    "end_s",
    "duration_s",
    "stance_s",
    "swing_s",
    "perturbed",
    "onset_s",
    "fraction_outlying_hip",
    "fraction_outlying_knee",
    "fraction_outlying_ankle",
    "removed",
    "reason",
    "rms_force_stance_n",
    "rms_force_swing_n",
    "max_abs_force_stance_n",
    "max_abs_force_swing_n",
]
FORCE_N = -3.5  # a constant interaction force: RMS and max |F| are 3.5 N in every phase


def _overground(n_heel_strikes: int, logged_from_s: float = 0.0):
    """Angles (128 Hz, 7 s), left events with ``n_heel_strikes`` heel strikes 1.2 s apart (each followed by a
    toe-off 0.72 s later) and a constant force, NaN before ``logged_from_s`` (outside the robot log)."""
    t = np.arange(0, 7.0, 1 / 128)
    phase = 2 * np.pi * (t - 0.5) / 1.2
    angles = pd.DataFrame(
        {
            "time_s": t,
            "hip_left_rad": 0.4 * np.sin(phase),
            "knee_left_rad": 0.6 * np.cos(phase),
            "ankle_left_rad": 0.2 * np.sin(phase + 1.0),
        }
    )
    hs = 0.5 + 1.2 * np.arange(n_heel_strikes)
    events = pd.DataFrame(
        {
            "side": pd.Series(["left"] * 2 * n_heel_strikes, dtype=object),
            "event": ["heel_strike", "toe_off"] * n_heel_strikes,
            "time_s": np.column_stack([hs, hs + 0.72]).ravel(),
            "sample": np.zeros(2 * n_heel_strikes, dtype=np.int64),
        }
    )
    force = pd.DataFrame(
        {
            "time_s": t,
            "force_measured_n": np.where(t >= logged_from_s, FORCE_N, np.nan),
            "perturbation": np.where(t >= logged_from_s, 0.0, np.nan),
        }
    )
    return angles, events, force


@pytest.mark.parametrize("n_heel_strikes, n_strides", [(0, 0), (1, 0), (2, 1)])
def test_zero_or_one_stride_gives_the_full_tables_flagged(n_heel_strikes, n_strides):
    angles, events, force = _overground(n_heel_strikes)
    with pytest.warns(TooFewStridesWarning) as caught:
        tables = stride_tables(angles, events, force, side="left")
    messages = [str(w.message) for w in caught]
    assert f"{n_strides} complete unperturbed left stride(s)" in messages[0]
    assert f"only {n_strides} valid stride(s), fewer than the 5 required" in messages[1]
    assert tables.too_few_strides
    s = tables.strides
    assert list(s.columns) == STRIDE_COLUMNS and len(s) == n_strides
    assert list(tables.cycles.columns) == [
        "stride",
        "phase",
        "point",
        "percent",
        "hip_left_rad",
        "knee_left_rad",
        "ankle_left_rad",
        "force_n",
    ]
    assert len(tables.cycles) == 3 * 101 * n_strides
    if n_strides:
        row = s.iloc[0]
        np.testing.assert_allclose(
            row[["heel_strike_s", "toe_off_s", "end_s", "duration_s", "stance_s", "swing_s"]].to_numpy(float),
            [0.5, 1.22, 1.7, 1.2, 0.72, 0.48],
            rtol=0,
            atol=1e-12,
        )
        assert not row.perturbed and not row.removed and row.reason == "" and np.isnan(row.onset_s)
        assert np.isnan(
            row[["fraction_outlying_hip", "fraction_outlying_knee", "fraction_outlying_ankle"]].to_numpy(float)
        ).all()
        np.testing.assert_allclose(row[STRIDE_COLUMNS[-4:]].to_numpy(float), 3.5, rtol=1e-12)
        np.testing.assert_allclose(tables.cycles["force_n"], FORCE_N, rtol=1e-12)


def test_strides_outside_the_robot_log_are_left_out_down_to_none():
    """NaN force before the robot log starts: the strides it does not cover are dropped, the others measured."""
    angles, events, force = _overground(5, logged_from_s=1.0)  # the first stride starts at 0.5 s, unlogged
    with pytest.warns(TooFewStridesWarning):
        tables = stride_tables(angles, events, force, side="left")
    np.testing.assert_allclose(tables.strides["heel_strike_s"], [1.7, 2.9, 4.1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(tables.strides[STRIDE_COLUMNS[-4:]].to_numpy(float), 3.5, rtol=1e-12)
    angles, events, force = _overground(2, logged_from_s=1.0)  # the only stride is unlogged
    with pytest.warns(TooFewStridesWarning):
        tables = stride_tables(angles, events, force, side="left")
    assert list(tables.strides.columns) == STRIDE_COLUMNS and len(tables.strides) == 0
    angles, events, force = _overground(2, logged_from_s=10.0)  # no robot log at all on these frames
    with pytest.warns(TooFewStridesWarning):
        tables = stride_tables(angles, events, force, side="left")
    assert list(tables.strides.columns) == STRIDE_COLUMNS and len(tables.strides) == 0


def test_stride_summary_of_an_untyped_empty_table_and_a_table_without_columns():
    empty = pd.DataFrame({c: pd.Series([], dtype=object) for c in STRIDE_COLUMNS})  # as read from a header-only TSV
    row = stride_summary({("S01", "walk"): empty}, min_valid=1).iloc[0]
    assert (row.n_strides, row.n_perturbed, row.n_removed, row.n_kept, row.status) == (0, 0, 0, 0, "too_few_strides")
    assert row.n_removed_hip == 0 and np.isnan(row.mean_stride_s)
    with pytest.raises(
        LoperInputError,
        match=r"S01 walk: stride table: column\(s\) \['removed', 'reason', "
        r"'duration_s'\] missing",
    ):
        stride_summary({("S01", "walk"): pd.DataFrame()})
