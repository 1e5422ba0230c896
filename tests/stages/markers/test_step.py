"""The markers step (loper_analysis.stages.markers.step.markers) on files written by others.

walking5.c3d (Vicon, from opensim-core) has 5 to 59 % of the frames of each
marker missing, most of them in long gaps and at the ends of the trial;
std_walking5_markers.trc is OpenSim's own reading of it (every 10th frame
and the last, values printed to 5 significant digits).
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import write_c3d
from loper_analysis.io.opensim_tables import read_markers
from loper_analysis.io.osim import quiet_opensim
from loper_analysis.motion.markers import GAP_REPORT_COLUMNS, GAP_SUMMARY_COLUMNS
from loper_analysis.stages.markers.step import TRIAL_MARKER_COLUMNS, MarkerSettings, markers

DATA = Path(__file__).parents[2] / "data" / "opensim-core"
WALKING5 = DATA / "walking5.c3d"


def _opensim_trc(path):
    """Times (n,), markers (n, m, 3) in the file's unit and labels, read by OpenSim's TRCFileAdapter."""
    osim = quiet_opensim()
    table = osim.TimeSeriesTableVec3(str(path))
    labels = list(table.getColumnLabels())
    t = np.array(table.getIndependentColumn(), dtype=float)
    flat_table = table.flatten(["_x", "_y", "_z"])  # keep every temporary alive while reading
    matrix = flat_table.getMatrix()
    values = np.array(matrix.to_numpy(), dtype=float, copy=True).reshape(t.size, len(labels), 3)
    assert table.getTableMetaDataAsString("Units") == "mm"
    return t, values, labels


def test_walking5_as_read_equals_opensims_reading(tmp_path):
    """No rotation, no filter, no filling: our TRC holds the numbers OpenSim read from the same file."""
    gaps = markers(
        WALKING5,
        tmp_path / "w5.trc",
        settings=MarkerSettings(rotation_deg=(0, 0, 0), cutoff_hz=None, max_gap_frames=0, walking_direction="fixed"),
    )
    assert len(gaps) == 0
    t, X_m, labels = read_markers(tmp_path / "w5.trc")
    t_ref, ref_mm, labels_ref = _opensim_trc(DATA / "std_walking5_markers.trc")
    assert labels == labels_ref and len(labels) == 40
    # times: the file's own clock (frame k at k / 250 s); the reference holds every 10th frame and the last
    assert len(t) == 1103
    np.testing.assert_allclose(t, np.arange(1103) / 250.0, rtol=0, atol=1e-12)
    frames = np.round(t_ref * 250.0).astype(int)
    assert frames[:3].tolist() == [0, 10, 20] and frames[-2:].tolist() == [1100, 1102]
    np.testing.assert_allclose(t[frames], t_ref, rtol=0, atol=1e-9)
    ours_mm = 1000.0 * X_m[frames]
    np.testing.assert_array_equal(np.isnan(ours_mm), np.isnan(ref_mm))  # missing in the same places
    both = np.isfinite(ref_mm)
    assert both.sum() == 7209
    diff = np.abs(ours_mm - ref_mm)[both]
    # the reference prints 5 significant digits: half a unit of the last digit (0.05 mm above 1 m) plus 1e-5 mm
    # (OpenSim's value differs from ours by up to 3e-6 mm, so a few values sit just past a rounding edge)
    half_unit = 0.5 * 10.0 ** (np.floor(np.log10(np.abs(ref_mm[both]))) - 4)
    assert np.all(diff <= half_unit + 1e-5), np.max(diff - half_unit)
    below_1m = np.abs(ref_mm[both]) < 1000.0
    assert below_1m.sum() == 5458
    assert diff[below_1m].max() < 0.01  # measured 0.0050 mm; 0.050 mm where the reference prints one decimal


def _runs(missing):
    edges = np.diff(np.r_[0, missing.astype(int), 0])
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1))


def test_walking5_through_the_default_chain_keeps_long_gaps_missing(tmp_path):
    """Filling, rotation and a 6 Hz low-pass on the real file: every gap of walking5 touches an end of the
    trial (the subject walks into and out of the volume), so nothing is filled and every gap stays NaN in the
    TRC; the reports count them."""
    raw = read_c3d(WALKING5).markers_m
    gaps = markers(
        WALKING5,
        tmp_path / "w5.trc",
        tmp_path / "w5.gaps.tsv",
        MarkerSettings(cutoff_hz=6.0, max_gap_frames=10),
        summary_out=tmp_path / "w5.markers.tsv",
    )
    _, X, labels = read_markers(tmp_path / "w5.trc")
    missing_raw = np.isnan(raw).any(axis=2)
    expected_rows, expected_filled = [], np.zeros_like(missing_raw)
    for j, label in enumerate(labels):
        for a, b in _runs(missing_raw[:, j]):
            if a > 0 and b < len(raw) - 1 and b - a + 1 <= 10:
                expected_rows.append({"marker": label, "first_frame": a, "last_frame": b, "n_frames": b - a + 1})
                expected_filled[a : b + 1, j] = True
    assert len(expected_rows) == 0
    assert gaps.to_dict("records") == expected_rows
    written = pd.read_csv(tmp_path / "w5.gaps.tsv", sep="\t")
    assert list(written.columns) == list(GAP_REPORT_COLUMNS) and len(written) == 0
    still = np.isnan(X).any(axis=2)
    np.testing.assert_array_equal(still, missing_raw & ~expected_filled)
    summary = pd.read_csv(tmp_path / "w5.markers.tsv", sep="\t")
    assert list(summary.columns) == ["label", *GAP_SUMMARY_COLUMNS, *TRIAL_MARKER_COLUMNS[1:]]
    assert summary["label"].tolist() == labels  # the file's labels (no prefix, no label map here)
    # frames with fewer than 3 markers: 0-134 (the subject outside the capture volume) and 1085-1102
    assert (summary["n_frames_too_few_markers"] == 153).all()
    np.testing.assert_array_equal(summary["n_filled_frames"], expected_filled.sum(axis=0))
    np.testing.assert_array_equal(summary["n_missing_frames"], still.sum(axis=0))
    assert summary["n_missing_frames"].tolist()[:3] == [57, 218, 269]
    assert summary["longest_gap_frames"].max() == 463
    assert (summary["n_unfiltered_frames"] == 0).all()
    columns = list(GAP_SUMMARY_COLUMNS)
    assert summary[columns].to_dict("records") == [{k: r[k] for k in columns} for r in gaps.attrs["per_marker"]]
    # walking toward -X, 1.6 m/s: the default (markers.walking_direction: auto) turns it half a turn to walk along +X
    assert summary["heading_deg"].iloc[0] == pytest.approx(182.37, abs=0.01) and (summary["turn_deg"] == 180).all()
    # the rotation by -90 deg about X took Vicon's Z up to Y up: the pelvis markers sit about 1 m high
    assert 0.8 < np.nanmedian(X[:, labels.index("RASI"), 1]) < 1.2


@pytest.fixture
def prefixed(tmp_path):
    X = np.random.default_rng(11).uniform(-1, 1, size=(60, 3, 3))
    X[20:23, 1] = np.nan  # filled
    X[:4, 0] = np.nan  # at the start: stays missing
    X[30:42, 2] = np.nan  # 12 frames, longer than 10: stays missing
    path = tmp_path / "prefixed.c3d"
    write_c3d(path, ["Anna:LASIS", "Anna:RASIS", "Anna:LHEE"], X, 100.0)
    return path


def test_prefixes_and_label_map_name_the_trc_columns_and_gaps(prefixed, tmp_path):
    gaps = markers(
        prefixed,
        tmp_path / "p.trc",
        settings=MarkerSettings(
            rotation_deg=(0, 0, 0),
            cutoff_hz=0,
            label_map={"LASIS": "LASI", "Anna:RASIS": "RASI"},
            required_markers=["LASI", "RASI", "LHEE"],
            walking_direction="fixed",
        ),
    )
    _, X, labels = read_markers(tmp_path / "p.trc")
    assert labels == ["LASI", "RASI", "LHEE"]
    assert gaps.to_dict("records") == [{"marker": "RASI", "first_frame": 20, "last_frame": 22, "n_frames": 3}]
    raw = read_c3d(prefixed).markers_m
    np.testing.assert_array_equal(np.isnan(X).any(axis=2).sum(axis=0), [4, 0, 12])
    np.testing.assert_allclose(X[[10, 59]], raw[[10, 59]], rtol=0, atol=1e-12)
    per_marker = pd.DataFrame(gaps.attrs["per_marker"])
    assert per_marker[["n_filled_frames", "n_missing_frames", "longest_gap_frames"]].values.tolist() == [
        [0, 4, 4],
        [3, 0, 0],
        [0, 12, 12],
    ]


def test_missing_model_markers_stop_the_step_before_writing(prefixed, tmp_path):
    with pytest.raises(LoperInputError) as err:
        markers(
            prefixed,
            tmp_path / "p.trc",
            settings=MarkerSettings(label_map={"LASIS": "LASI"}, required_markers=["LASI", "RASI", "RHEE"]),
        )
    assert str(err.value).startswith(f"{prefixed}: model marker(s) RASI, RHEE not provided by any label")
    with pytest.raises(LoperInputError, match=r"markers.label_map: label\(s\) L_ASIS not in the file"):
        markers(prefixed, tmp_path / "p.trc", settings=MarkerSettings(label_map={"L_ASIS": "LASI"}))
    assert not (tmp_path / "p.trc").exists()


def test_time_base_of_a_file_not_starting_at_frame_one(prefixed, tmp_path):
    """First frame 101 at 100 Hz: the TRC's times start at 1.00 s, and a 0.1 s static cut keeps 1.00..1.09 s."""
    data = bytearray(prefixed.read_bytes())
    data[6:10] = struct.pack("<HH", 101, 160)
    late = tmp_path / "late.c3d"
    late.write_bytes(bytes(data))
    markers(
        late,
        tmp_path / "late.trc",
        settings=MarkerSettings(rotation_deg=(0, 0, 0), cutoff_hz=None, walking_direction="fixed"),
    )
    t, _, _ = read_markers(tmp_path / "late.trc")
    np.testing.assert_allclose(t, 1.0 + np.arange(60) / 100.0, rtol=0, atol=1e-12)
    markers(
        late,
        tmp_path / "cut.trc",
        settings=MarkerSettings(rotation_deg=(0, 0, 0), cutoff_hz=None, duration_s=0.1, walking_direction="fixed"),
    )
    t, _, _ = read_markers(tmp_path / "cut.trc")
    np.testing.assert_allclose(t, 1.0 + np.arange(10) / 100.0, rtol=0, atol=1e-12)


#: Labels as BTS exports them: inner spaces.
BTS_LABELS = ["r heel", "l heel", "r toe tip", "sacrum"]


@pytest.fixture
def bts(tmp_path):
    X = np.random.default_rng(12).uniform(-1, 1, size=(60, 4, 3))
    path = tmp_path / "bts.c3d"
    write_c3d(path, BTS_LABELS, X, 100.0)
    return path


@pytest.mark.parametrize(
    "label_map, names",
    [
        (None, BTS_LABELS),
        ({"r heel": "RHEE", "l heel": "LHEE"}, ["RHEE", "LHEE", "r toe tip", "sacrum"]),
    ],
)
def test_labels_with_spaces_through_the_markers_step(bts, tmp_path, label_map, names):
    """Labels with spaces are read, mapped (a key with spaces) or kept, and written to a TRC that our reader and
    OpenSim's read back to the same labels and the C3D's numbers."""
    assert read_c3d(bts).marker_labels == BTS_LABELS
    markers(
        bts,
        tmp_path / "bts.trc",
        settings=MarkerSettings(
            rotation_deg=(0, 0, 0),
            cutoff_hz=None,
            label_map=label_map,
            required_markers=[n for n in names if " " not in n],
            walking_direction="fixed",
        ),
    )
    t, X, labels = read_markers(tmp_path / "bts.trc")
    assert labels == names
    np.testing.assert_allclose(t, np.arange(60) / 100.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(X, read_c3d(bts).markers_m, rtol=0, atol=1e-12)
    t_ref, ref_mm, labels_ref = _opensim_trc(tmp_path / "bts.trc")
    assert labels_ref == names
    np.testing.assert_array_equal(t_ref, t)
    np.testing.assert_array_equal(ref_mm / 1000.0, X)
    osim = quiet_opensim()
    assert list(osim.TRCFileAdapter().read(str(tmp_path / "bts.trc"))["markers"].getColumnLabels()) == names


def test_a_label_map_value_with_a_space_is_refused_naming_the_rule(bts, tmp_path):
    """OpenSim refuses whitespace in a model marker's name, so a map value cannot hold one."""
    with pytest.raises(
        LoperInputError,
        match=r"bts\.c3d: markers\.label_map: 'r heel' maps to 'R HEE', not a "
        r"marker name \(non-empty, no spaces: OpenSim refuses whitespace",
    ):
        markers(bts, tmp_path / "bts.trc", settings=MarkerSettings(label_map={"r heel": "R HEE"}))
    assert not (tmp_path / "bts.trc").exists()


def test_label_maps_merge_in_order_and_a_static_only_label_needs_no_entry_elsewhere(prefixed, tmp_path):
    # the map of every trial, then the static trial's own: a label only the static trial has maps there
    static = tmp_path / "static.c3d"
    X = np.random.default_rng(12).uniform(-1, 1, size=(20, 4, 3))
    write_c3d(static, ["Anna:LASIS", "Anna:RASIS", "Anna:LHEE", "Anna:L_MED_KNEE"], X, 100.0)
    every, static_only = {"LASIS": "LASI", "RASIS": "RASI"}, {"L_MED_KNEE": "LKNM", "RASIS": "RASI_static"}
    markers(
        static,
        tmp_path / "s.trc",
        settings=MarkerSettings(
            rotation_deg=(0, 0, 0), cutoff_hz=0, label_map=[every, static_only], walking_direction="fixed"
        ),
        summary_out=tmp_path / "s.markers.tsv",
    )
    assert read_markers(tmp_path / "s.trc")[2] == ["LASI", "RASI_static", "LHEE", "LKNM"]  # the later map wins
    summary = pd.read_csv(tmp_path / "s.markers.tsv", sep="\t")
    assert summary["label"].tolist() == ["Anna:LASIS", "Anna:RASIS", "Anna:LHEE", "Anna:L_MED_KNEE"]
    markers(
        prefixed,
        tmp_path / "w.trc",
        settings=MarkerSettings(rotation_deg=(0, 0, 0), cutoff_hz=0, label_map=[every], walking_direction="fixed"),
    )
    assert read_markers(tmp_path / "w.trc")[2] == ["LASI", "RASI", "LHEE"]
    with pytest.raises(
        LoperInputError, match=r"prefixed\.c3d: markers\.label_map: label\(s\) L_MED_KNEE not in the file"
    ):
        markers(
            prefixed, tmp_path / "never.trc", settings=MarkerSettings(label_map=[every, static_only])
        )  # the static map on a walking trial


def test_a_span_crops_the_trial_on_the_files_clock(prefixed, tmp_path):
    markers(
        prefixed,
        tmp_path / "c.trc",
        settings=MarkerSettings(rotation_deg=(0, 0, 0), cutoff_hz=0, span_s=(0.1, 0.3), walking_direction="fixed"),
        summary_out=tmp_path / "c.markers.tsv",
    )
    t, X, _ = read_markers(tmp_path / "c.trc")
    np.testing.assert_allclose(t, np.arange(10, 31) / 100.0, atol=1e-12)
    summary = pd.read_csv(tmp_path / "c.markers.tsv", sep="\t").iloc[0]
    assert (summary.n_frames, summary.first_time_s, summary.last_time_s) == (21, 0.1, 0.3)
    with pytest.raises(
        LoperInputError,
        match=r"prefixed\.c3d: the trial's span 5 \.\. 6 s \(markers\.trial_spans_s\) "
        r"holds no frame of the file \(0\.0000 \.\. 0\.5900 s\)",
    ):
        markers(prefixed, tmp_path / "never.trc", settings=MarkerSettings(span_s=(5.0, 6.0)))
    assert not (tmp_path / "never.trc").exists()


def _standing_markers(rng, n_frames: int = 50) -> np.ndarray:
    """Four markers about a standing subject in a Z-up lab (m): pelvis about 1 m high, feet on the floor."""
    base = np.array([[0.10, 0.12, 1.00], [0.10, -0.12, 1.00], [0.05, 0.10, 0.08], [0.05, -0.10, 0.08]])
    return base + rng.normal(scale=0.002, size=(n_frames, 4, 3))


@pytest.mark.parametrize("point_unit", ["mm", "cm", "m"])
def test_a_written_c3d_reaches_the_trc_in_metres_in_the_model_s_y_up_frame(point_unit, rng, tmp_path):
    """The default lab -> model rotation, -90 deg about X, takes the lab's (x, y, z) to the model's (x, z, -y),
    whatever length unit the file declares."""
    lab = _standing_markers(rng)
    c3d = write_c3d(tmp_path / "stand.c3d", ["LASI", "RASI", "LTOE", "RTOE"], lab, 100.0, point_unit=point_unit)
    gaps = markers(
        c3d,
        tmp_path / "stand.trc",
        settings=MarkerSettings(cutoff_hz=None, walking_direction="fixed"),
        lab_angles_out=tmp_path / "lab_angles.tsv",
    )
    t, X, labels = read_markers(tmp_path / "stand.trc")
    assert labels == ["LASI", "RASI", "LTOE", "RTOE"]
    np.testing.assert_allclose(t, np.arange(50) / 100.0, rtol=0, atol=1e-12)
    model = np.stack([lab[..., 0], lab[..., 2], -lab[..., 1]], axis=-1)
    np.testing.assert_allclose(X, model, rtol=0, atol=1e-6)  # float32 in the file's unit
    assert len(gaps) == 0 and gaps.attrs["per_marker"][0]["turn_deg"] == 0
    assert (tmp_path / "lab_angles.tsv").read_text() == "time_s\n"  # no lab angles in the file: the header alone


def test_a_trial_walking_along_the_lab_s_minus_y_is_turned_to_walk_along_the_model_s_plus_x(rng, tmp_path):
    n, rate, speed = 200, 100.0, 1.2
    lab = _standing_markers(rng, n)
    lab[..., 1] -= speed * np.arange(n)[:, None] / rate  # walks toward the lab's -Y
    c3d = write_c3d(tmp_path / "walk.c3d", ["LASI", "RASI", "LTOE", "RTOE"], lab, rate)
    markers(c3d, tmp_path / "walk.trc", settings=MarkerSettings(cutoff_hz=None), summary_out=tmp_path / "s.tsv")
    _, X, _ = read_markers(tmp_path / "walk.trc")
    pelvis = X[:, :2].mean(axis=1)
    velocity = (pelvis[-1] - pelvis[0]) / ((n - 1) / rate)
    np.testing.assert_allclose(velocity, [speed, 0.0, 0.0], atol=0.01)
    np.testing.assert_allclose(X[..., 1], lab[..., 2], atol=1e-6)  # heights: the lab's Z, the model's Y
    summary = pd.read_csv(tmp_path / "s.tsv", sep="\t").iloc[0]
    assert summary.heading_deg == pytest.approx(270.0, abs=0.5)  # 0 deg along +X, 90 deg along -Z
    assert summary.turn_deg == pytest.approx(90.0)
