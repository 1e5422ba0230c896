"""The impedance-study figures (loper_analysis.report.figures.impedance) and their tables, from small known tables."""

from __future__ import annotations

import pandas as pd
import pytest
from matplotlib.figure import Figure

from loper_analysis.constants import JOINTS, PARAMETERS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.report.figures import pyplot
from loper_analysis.report.figures.impedance import (
    fit_figure,
    impedance_figure,
    impedance_means,
    response_peaks,
    responses_figure,
)
from tests.report.figures.impedance_tables import (
    AMPLITUDE_RAD,
    curves_table,
    impedance_table,
    response_table,
)

plt = pyplot()  # the Agg backend


@pytest.fixture
def figures():
    """Close every figure a test leaves open; yields the list to put them in."""
    made: list = []
    yield made
    for fig in made:
        plt.close(fig)


def _texts(ax) -> list[str]:
    return [t.get_text() for t in ax.texts]


def test_response_peaks_and_missing():
    peaks = response_peaks({300: pd.DataFrame(), 50: response_table(1.0), 175: response_table(2.0)})
    assert list(peaks.index) == [50, 175, 300]
    assert list(peaks.columns) == list(JOINTS)
    for joint in JOINTS:
        assert peaks.loc[50, joint] == pytest.approx(AMPLITUDE_RAD[joint], rel=1e-9)
        assert peaks.loc[175, joint] == pytest.approx(2 * AMPLITUDE_RAD[joint], rel=1e-9)
    assert peaks.loc[300].isna().all()


def test_responses_figure_has_a_column_per_onset_and_says_missing(figures):
    fig = responses_figure({300: pd.DataFrame(), 50: response_table(1.0), 175: response_table(2.0)}, title="S01")
    figures.append(fig)
    assert isinstance(fig, Figure)
    axes = fig.get_axes()
    assert len(axes) == 2 * len(JOINTS) * 3  # angles and difference per joint, one column per onset
    assert [ax.get_title() for ax in axes[:3]] == ["onset 50 ms (n = 12)", "onset 175 ms (n = 12)", "onset 300 ms"]
    assert all(_texts(ax) == ["missing"] for ax in axes[2::3])  # the 300 ms column, in row-major order
    assert fig.get_suptitle() == "S01"


def test_header_only_response_table_is_missing(figures):
    empty = response_table().iloc[:0]
    assert response_peaks({50: empty}).loc[50].isna().all()
    fig = responses_figure({50: empty})
    figures.append(fig)
    assert all(_texts(ax) == ["missing"] for ax in fig.get_axes())


def test_missing_response_column_names_table_and_column():
    bad = {50: response_table().drop(columns="knee_rad_sd")}
    open_before = plt.get_fignums()
    with pytest.raises(LoperInputError, match=r"bad\.tsv.*knee_rad_sd"):
        responses_figure(bad, sources={50: "bad.tsv"})
    with pytest.raises(LoperInputError, match=r"bad\.tsv.*knee_rad_sd"):
        response_peaks(bad, sources={50: "bad.tsv"})
    assert plt.get_fignums() == open_before  # no half-drawn figure left open


def test_fit_figure_and_not_fitted(figures):
    fig = fit_figure({50: curves_table(), 175: pd.DataFrame(columns=["time_s"])}, title="fit")
    figures.append(fig)
    axes = fig.get_axes()
    assert len(axes) == len(JOINTS) * 2
    assert all(len(ax.get_lines()) == 3 for ax in axes[0::2])  # measured, model, zero line
    assert all(_texts(ax) == ["not fitted"] for ax in axes[1::2])


def test_fit_figure_missing_column_names_table_and_column():
    with pytest.raises(LoperInputError, match=r"c\.tsv.*ankle_model_rad"):
        fit_figure({50: curves_table().drop(columns="ankle_model_rad")}, sources={50: "c.tsv"})


def test_impedance_means_match_hand_means():
    table = impedance_table()
    mean = impedance_means(table)
    assert list(mean.index) == [50, 175, 300]
    assert mean.index.dtype.kind == "i"
    assert list(mean.columns) == list(PARAMETERS)
    kept = table[table.status.isin(["ok", "not_identifiable"])]
    for onset in (50, 175, 300):
        for joint in JOINTS:
            for kind in ("K", "D"):
                sel = kept[(kept.onset_ms == onset) & (kept.joint == joint)][parameter_column(kind)]
                assert mean.loc[onset, f"{kind}_{joint}"] == pytest.approx(sel.mean(), rel=1e-12)
    # explicit spot checks: 175 ms has only S01 and SYN1; 50 ms knee excludes the skipped SYN1 row
    both = table[(table.onset_ms == 175) & (table.joint == "hip") & table.subject.isin(["S01", "SYN1"])]
    assert mean.loc[175, "K_hip"] == pytest.approx(both.K_nm_per_rad.sum() / 2)
    two = table[(table.onset_ms == 50) & (table.joint == "knee") & table.subject.isin(["S01", "S02"])]
    assert mean.loc[50, "D_knee"] == pytest.approx(two.D_nms_per_rad.sum() / 2)


def test_impedance_figure_has_k_and_d_per_joint(figures):
    fig = impedance_figure(impedance_table())
    figures.append(fig)
    assert [ax.get_title() for ax in fig.get_axes()] == ["K_hip", "K_knee", "K_ankle", "D_hip", "D_knee", "D_ankle"]


def test_hip_knee_only_table_has_no_ankle(figures):
    table = impedance_table()
    table = table[table.joint != "ankle"]
    mean = impedance_means(table)
    assert mean[["K_ankle", "D_ankle"]].isna().all().all()
    assert mean[["K_hip", "D_hip", "K_knee", "D_knee"]].notna().all().all()
    fig = impedance_figure(table)
    figures.append(fig)
    assert [ax.get_title() for ax in fig.get_axes()] == ["K_hip", "K_knee", "D_hip", "D_knee"]


def test_bad_impedance_tables_name_table_column_and_value():
    table = impedance_table()
    with pytest.raises(LoperInputError, match=r"noK\.tsv.*'K_nm_per_rad'"):
        impedance_figure(table.drop(columns="K_nm_per_rad"), source="noK.tsv")
    with pytest.raises(LoperInputError, match=r"noK\.tsv.*'K_nm_per_rad'"):
        impedance_means(table.drop(columns="K_nm_per_rad"), source="noK.tsv")
    bad = table.copy()
    bad.loc[bad.index[0], "joint"] = "elbow"
    with pytest.raises(LoperInputError, match=r"elbow\.tsv.*joint.*elbow"):
        impedance_figure(bad, source="elbow.tsv")
