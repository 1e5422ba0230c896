"""The figure steps of the impedance study (loper_analysis.stages.impedance.step): PNG files from TSV tables on disk."""

from __future__ import annotations

import pandas as pd
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.report.figures.impedance import impedance_means
from loper_analysis.stages.impedance.step import impedance_figure, subject_figures
from tests.report.figures.impedance_tables import (
    AMPLITUDE_RAD,
    curves_table,
    impedance_table,
    response_table,
)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _assert_png(path, min_bytes=5_000):
    data = path.read_bytes()
    assert data.startswith(PNG_MAGIC)
    assert min_bytes < len(data) < 5_000_000
    assert not list(path.parent.glob(f".{path.name}.*"))  # no staging left beside it


def _write(table: pd.DataFrame, path):
    table.to_csv(path, sep="\t", index=False)
    return path


def test_subject_figures_write_both_pngs_and_return_peaks(tmp_path):
    """300 ms is missing (an empty file); 175 ms was not fitted (a header-only curve table)."""
    responses = [
        _write(response_table(1.0), tmp_path / "r50.tsv"),
        _write(response_table(2.0), tmp_path / "r175.tsv"),
        tmp_path / "r300.tsv",
    ]
    responses[2].write_text("")
    curves = [_write(curves_table(), tmp_path / "c50.tsv"), tmp_path / "c175.tsv", tmp_path / "c300.tsv"]
    curves[1].write_text("time_s\n")
    curves[2].write_text("")
    peaks = subject_figures([50, 175, 300], responses, curves, "S01", tmp_path / "responses.png", tmp_path / "fit.png")
    _assert_png(tmp_path / "responses.png")
    _assert_png(tmp_path / "fit.png")
    assert list(peaks.index) == [50, 175, 300]
    for joint in JOINTS:
        assert peaks.loc[50, joint] == pytest.approx(AMPLITUDE_RAD[joint], rel=1e-9)
        assert peaks.loc[175, joint] == pytest.approx(2 * AMPLITUDE_RAD[joint], rel=1e-9)
    assert peaks.loc[300].isna().all()


def test_header_only_response_file_still_gives_figures(tmp_path):
    response = _write(response_table().iloc[:0], tmp_path / "r.tsv")
    curve = _write(curves_table().iloc[:0], tmp_path / "c.tsv")
    peaks = subject_figures([50], [response], [curve], "S01", tmp_path / "r.png", tmp_path / "f.png")
    _assert_png(tmp_path / "r.png", min_bytes=1_000)
    _assert_png(tmp_path / "f.png", min_bytes=1_000)
    assert peaks.loc[50].isna().all()


def test_missing_response_column_names_file_and_column_and_writes_nothing(tmp_path):
    response = _write(response_table().drop(columns="knee_rad_sd"), tmp_path / "bad.tsv")
    curve = _write(curves_table(), tmp_path / "c.tsv")
    with pytest.raises(LoperInputError, match=r"bad\.tsv.*knee_rad_sd"):
        subject_figures([50], [response], [curve], "S01", tmp_path / "x.png", tmp_path / "fit.png")
    assert not (tmp_path / "x.png").exists() and not (tmp_path / "fit.png").exists()


def test_missing_curve_column_names_file_and_column(tmp_path):
    response = _write(response_table(), tmp_path / "r.tsv")
    curve = _write(curves_table().drop(columns="ankle_model_rad"), tmp_path / "c.tsv")
    with pytest.raises(LoperInputError, match=r"c\.tsv.*ankle_model_rad"):
        subject_figures([50], [response], [curve], "S01", tmp_path / "r.png", tmp_path / "fit.png")
    assert not (tmp_path / "fit.png").exists()


def test_impedance_figure_writes_png_and_returns_the_means(tmp_path):
    table = impedance_table()
    out = tmp_path / "impedance.png"
    mean = impedance_figure(_write(table, tmp_path / "impedance.tsv"), out)
    _assert_png(out)
    pd.testing.assert_frame_equal(mean, impedance_means(table), rtol=1e-12)


def test_impedance_figure_of_bad_files_names_them_and_writes_nothing(tmp_path):
    table = impedance_table()
    out = tmp_path / "y.png"
    with pytest.raises(LoperInputError, match=r"noK\.tsv.*'K_nm_per_rad'"):
        impedance_figure(_write(table.drop(columns="K_nm_per_rad"), tmp_path / "noK.tsv"), out)
    bad = table.copy()
    bad.loc[bad.index[0], "joint"] = "elbow"
    with pytest.raises(LoperInputError, match=r"elbow\.tsv.*joint.*elbow"):
        impedance_figure(_write(bad, tmp_path / "elbow.tsv"), out)
    with pytest.raises(LoperInputError, match=r"absent\.tsv: impedance table not found"):
        impedance_figure(tmp_path / "absent.tsv", out)
    assert not out.exists()
