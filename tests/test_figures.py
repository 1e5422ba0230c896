"""Tests of loper_analysis.figures: figures drawn from small TSVs with known contents."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import JOINTS, PARAMETERS
from loper_analysis.errors import LoperInputError
from loper_analysis.figures import plot_fit, plot_impedance, plot_responses

AMPLITUDE_RAD = {"hip": 0.05, "knee": 0.12, "ankle": 0.02}
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _assert_png(path, min_bytes=5_000):
    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC)
    assert min_bytes < len(data) < 5_000_000
    assert not list(path.parent.glob(f".{path.name}.*.tmp"))


def _response_table(scale: float = 1.0) -> pd.DataFrame:
    t = np.arange(-125, 301) / 1000.0  # 1 kHz grid; the 5 Hz sine peaks on it at 50 ms
    table = {"time_s": t}
    for joint in JOINTS:
        base = 0.3 * np.cos(2 * np.pi * t)
        diff = scale * AMPLITUDE_RAD[joint] * np.sin(2 * np.pi * 5.0 * t)
        table[f"{joint}_rad_mean"] = diff
        table[f"{joint}_rad_sd"] = np.full_like(t, 0.01)
        table[f"{joint}_perturbed_rad_mean"] = base + diff
        table[f"{joint}_unperturbed_rad_mean"] = base
    table["force_n_mean"] = 10 * np.sin(2 * np.pi * 4.0 * t)
    table["force_n_sd"] = 1.0
    table["n_pairs"] = 12
    table["analysis_window"] = (t >= -0.025) & (t <= 0.25)
    return pd.DataFrame(table)


def _write(table: pd.DataFrame, path):
    table.to_csv(path, sep="\t", index=False)
    return path


def test_plot_responses_peaks_and_missing(tmp_path):
    p50 = _write(_response_table(1.0), tmp_path / "r50.tsv")
    p175 = _write(_response_table(2.0), tmp_path / "r175.tsv")
    p300 = tmp_path / "r300.tsv"
    p300.write_text("")  # missing onset: no rows
    out = tmp_path / "responses.png"
    peaks = plot_responses({300: p300, 50: p50, 175: p175}, out, title="S01")
    _assert_png(out)
    assert list(peaks.index) == [50, 175, 300]
    assert list(peaks.columns) == list(JOINTS)
    for joint in JOINTS:
        assert peaks.loc[50, joint] == pytest.approx(AMPLITUDE_RAD[joint], rel=1e-9)
        assert peaks.loc[175, joint] == pytest.approx(2 * AMPLITUDE_RAD[joint], rel=1e-9)
    assert peaks.loc[300].isna().all()


def test_plot_responses_header_only_is_missing(tmp_path):
    p = tmp_path / "r.tsv"
    _write(_response_table().iloc[:0], p)
    out = tmp_path / "r.png"
    peaks = plot_responses({50: p}, out)
    _assert_png(out, min_bytes=1_000)
    assert peaks.loc[50].isna().all()


def test_plot_responses_missing_column_names_file_and_column(tmp_path):
    p = _write(_response_table().drop(columns="knee_rad_sd"), tmp_path / "bad.tsv")
    with pytest.raises(LoperInputError, match=r"bad\.tsv.*knee_rad_sd"):
        plot_responses({50: p}, tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists()


def _curves_table() -> pd.DataFrame:
    t = np.arange(0.0, 0.2751, 0.001)
    table = {"time_s": t}
    for joint in JOINTS:
        measured = AMPLITUDE_RAD[joint] * np.sin(2 * np.pi * 4.0 * t)
        table[f"{joint}_measured_rad"] = measured + 0.002 * np.cos(2 * np.pi * 30 * t)
        table[f"{joint}_model_rad"] = measured
    return pd.DataFrame(table)


def test_plot_fit_and_not_fitted(tmp_path):
    p50 = _write(_curves_table(), tmp_path / "c50.tsv")
    p175 = tmp_path / "c175.tsv"
    p175.write_text("time_s\n")  # not fitted
    out = tmp_path / "fit.png"
    assert plot_fit({50: p50, 175: p175}, out, title="fit") is None
    _assert_png(out)


def test_plot_fit_missing_column(tmp_path):
    p = _write(_curves_table().drop(columns="ankle_model_rad"), tmp_path / "c.tsv")
    with pytest.raises(LoperInputError, match=r"c\.tsv.*ankle_model_rad"):
        plot_fit({50: p}, tmp_path / "fit.png")


def _impedance_table() -> pd.DataFrame:
    rng = np.random.default_rng(3)
    rows = []
    for subject, synthetic in (("S01", False), ("S02", False), ("SYN1", True)):
        for onset in (50, 175, 300):
            for joint in JOINTS:
                k, d = rng.uniform(5, 80), rng.uniform(0.1, 3)
                status = "ok"
                if subject == "S02" and onset == 175:
                    status = "failed"  # broken line; K/D empty
                rows.append({
                    "subject": subject, "onset_ms": onset, "joint": joint,
                    "K": np.nan if status == "failed" else k, "D": np.nan if status == "failed" else d,
                    "K_ci95_low": k - 1, "K_ci95_high": k + 1, "D_ci95_low": d - 0.1, "D_ci95_high": d + 0.1,
                    "vaf_pct": 90.0, "n_strides": 20,
                    "K_true": k * 1.05 if synthetic else np.nan, "D_true": d * 0.95 if synthetic else np.nan,
                    "K_error": -0.05 * k if synthetic else np.nan, "D_error": 0.05 * d if synthetic else np.nan,
                    "cost_rad2": 1e-4, "status": status, "reason": "" if status == "ok" else "diverged",
                })
    table = pd.DataFrame(rows)
    # a row marked not_identifiable still counts; a "skipped" row with stray values does not
    table.loc[(table.subject == "S01") & (table.onset_ms == 300) & (table.joint == "hip"), "status"] = \
        "not_identifiable"
    table.loc[(table.subject == "SYN1") & (table.onset_ms == 50) & (table.joint == "knee"), "status"] = "skipped"
    return table


def test_plot_impedance_mean_matches_hand_mean(tmp_path):
    table = _impedance_table()
    p = _write(table, tmp_path / "impedance.tsv")
    out = tmp_path / "impedance.png"
    mean = plot_impedance(p, out)
    _assert_png(out)
    assert list(mean.index) == [50, 175, 300]
    assert mean.index.dtype.kind == "i"
    assert list(mean.columns) == list(PARAMETERS)
    kept = table[table.status.isin(["ok", "not_identifiable"])]
    for onset in (50, 175, 300):
        for joint in JOINTS:
            for kind in ("K", "D"):
                sel = kept[(kept.onset_ms == onset) & (kept.joint == joint)][kind]
                assert mean.loc[onset, f"{kind}_{joint}"] == pytest.approx(sel.mean(), rel=1e-12)
    # explicit spot checks: 175 ms has only S01 and SYN1; 50 ms knee excludes the skipped SYN1 row
    both = table[(table.onset_ms == 175) & (table.joint == "hip") & table.subject.isin(["S01", "SYN1"])]
    assert mean.loc[175, "K_hip"] == pytest.approx(both.K.sum() / 2)
    two = table[(table.onset_ms == 50) & (table.joint == "knee") & table.subject.isin(["S01", "S02"])]
    assert mean.loc[50, "D_knee"] == pytest.approx(two.D.sum() / 2)


def test_plot_impedance_hip_knee_only_and_errors(tmp_path):
    table = _impedance_table()
    table = table[table.joint != "ankle"]
    out = tmp_path / "hk.png"
    mean = plot_impedance(_write(table, tmp_path / "hk.tsv"), out)
    _assert_png(out)
    assert mean[["K_ankle", "D_ankle"]].isna().all().all()
    assert mean[["K_hip", "D_hip", "K_knee", "D_knee"]].notna().all().all()

    with pytest.raises(LoperInputError, match=r"noK\.tsv.*'K'"):
        plot_impedance(_write(table.drop(columns="K"), tmp_path / "noK.tsv"), tmp_path / "y.png")
    bad = table.copy()
    bad.loc[bad.index[0], "joint"] = "elbow"
    with pytest.raises(LoperInputError, match=r"joint.*elbow"):
        plot_impedance(_write(bad, tmp_path / "elbow.tsv"), tmp_path / "y.png")
    with pytest.raises(LoperInputError, match="does not exist"):
        plot_impedance(tmp_path / "absent.tsv", tmp_path / "y.png")
    assert not (tmp_path / "y.png").exists()
