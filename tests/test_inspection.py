"""``loper-analysis inspect`` (inspection, lab_frame, label_matching, steps.inspect) against known answers.

Files: walking5.c3d (Vicon, opensim-core's tests: Z up, walking toward -X, two TYPE-2 plates), whose
numbers are recomputed here with numpy from read_c3d and read_force_platforms; and two files written
with the project's C3D writer whose every number is known by construction: a Z-up lab walking +X
(first frame 30, one plate listed clockwise, resting at -15 N, events) and a Y-up lab walking +X
(one plate listed counter-clockwise, resting at -12 N). Labels are matched against gait2392 with its
scale marker set and, when the copy is there, Rajagopal2016.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from loper_analysis.cli import main
from loper_analysis.inspection import config_snippet, marker_presence, sparse_frames
from loper_analysis.io.c3d import read_c3d
from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.io.force_platforms import read_force_platforms
from loper_analysis.io.readers import read_label_map
from loper_analysis.motion.lab_frame import vertical_axis, walking_direction
from loper_analysis.motion.label_matching import heel_markers, match_labels, starter_label_map
from loper_analysis.motion.marker_names import model_marker_names
from loper_analysis.schema import check_config
from loper_analysis.stages.inspect import inspect_c3d, model_marker_names_of

ROOT = Path(__file__).resolve().parents[1]
WALKING5 = ROOT / "tests" / "data" / "opensim-core" / "walking5.c3d"
GAIT2392 = ROOT / "examples" / "gait2392" / "gait2392_simbody.osim"
MARKER_SET = ROOT / "examples" / "gait2392" / "gait2392_Scale_MarkerSet.xml"
QTM_MAP = ROOT / "examples" / "gait2392" / "qtm_label_map.tsv"
RAJAGOPAL = ROOT / "tests" / "data" / "rajagopal2016" / "Rajagopal2016.osim"

# ---------------------------------------------------------------- files built here

RATE_HZ, RATIO, N_FRAMES, FIRST_FRAME = 100.0, 10, 200, 30
LABELS = [
    "Subj:HEAD",
    "Subj:LASI",
    "Subj:RASI",
    "Subj:LKNE",
    "Subj:RKNE",
    "Subj:LHEE",
    "Subj:RHEE",
    "Subj:LTOE",
    "Subj:RTOE",
]
SPEED_M_PER_S = 1.2
CHANNELS = ["Fx1", "Fy1", "Fz1", "Mx1", "My1", "Mz1"]


def _walker() -> np.ndarray:
    """(200, 9, 3) m as (forward, left, up): walking at 1.2 m/s, legs swinging +-0.3 m, with known gaps.

    Presence: frames 0-4 hold no marker, frames 5-7 only HEAD and LASI; LKNE misses 50-59 (10 frames);
    LTOE is present 20-189 but for 120-122 (3 frames).
    """
    t = np.arange(N_FRAMES) / RATE_HZ
    swing = 0.3 * np.sin(2 * np.pi * t)
    rows = [
        (0, 0, 1.7),
        (0.05, 0.12, 0.95),
        (0.05, -0.12, 0.95),
        (0.1, 0.1, 0.5),
        (0.1, -0.1, 0.5),
        (-0.05, 0.1, 0.05),
        (-0.05, -0.1, 0.05),
        (0.15, 0.1, 0.03),
        (0.15, -0.1, 0.03),
    ]
    X = np.zeros((N_FRAMES, len(rows), 3))
    for j, (fwd, left, up) in enumerate(rows):
        leg = (swing if left > 0 else -swing) if j >= 3 else 0.0
        X[:, j] = np.column_stack(
            [0.2 + SPEED_M_PER_S * t + fwd + leg, np.full(N_FRAMES, left), up + 0.02 * np.sin(4 * np.pi * t)]
        )
    X[50:60, 3] = np.nan
    X[:20, 7] = X[190:, 7] = X[120:123, 7] = np.nan
    X[:5] = np.nan
    X[5:8, 2:] = np.nan
    return X


def _load_n() -> np.ndarray:
    """Upward force on the body above rest at 1000 Hz: a half sine of 800 N from 0.8 to 1.4 s, peak at sample 1100."""
    t = np.arange(N_FRAMES * RATIO) / (RATE_HZ * RATIO)
    return np.where((t >= 0.8) & (t <= 1.4), 800.0 * np.sin(np.pi * (t - 0.8) / 0.6), 0.0)


@pytest.fixture(scope="module")
def zup_file(tmp_path_factory) -> Path:
    """Z-up lab walking +X; plate z down (corners clockwise seen from above), resting at -15 N; two events."""
    path = tmp_path_factory.mktemp("zup") / "zup.c3d"
    ch = np.zeros((N_FRAMES * RATIO, 6))
    ch[:, 2] = -(_load_n() - 15.0)  # plate z points down: the Fz channel is minus the upward force on the body
    plate = ForcePlatform(
        2, [(1.3, 0.1, 0.0), (0.7, 0.1, 0.0), (0.7, 0.5, 0.0), (1.3, 0.5, 0.0)], (0, 0, -0.04), (1, 2, 3, 4, 5, 6)
    )
    write_c3d(
        path,
        LABELS,
        _walker(),
        RATE_HZ,
        CHANNELS,
        ch,
        ["N"] * 3 + ["Nmm"] * 3,
        RATE_HZ * RATIO,
        first_frame=FIRST_FRAME,
        force_platforms=[plate],
        events=[("Left", "Foot Strike", 0.9), ("Right", "Foot Off", 1.25)],
    )
    return path


@pytest.fixture(scope="module")
def yup_file(tmp_path_factory) -> Path:
    """Y-up lab (x forward, y up, z right) walking +X, in m; plate z up (corners counter-clockwise), rest -12 N."""
    path = tmp_path_factory.mktemp("yup") / "yup.c3d"
    W = _walker()
    X = np.stack([W[..., 0], W[..., 2], -W[..., 1]], axis=-1)
    ch = np.zeros((N_FRAMES * RATIO, 6))
    ch[:, 2] = _load_n() - 12.0
    plate = ForcePlatform(
        2, [(1.3, 0.0, 0.1), (0.7, 0.0, 0.1), (0.7, 0.0, 0.5), (1.3, 0.0, 0.5)], (0, 0, 0.04), (1, 2, 3, 4, 5, 6)
    )
    write_c3d(
        path,
        LABELS,
        X,
        RATE_HZ,
        CHANNELS,
        ch,
        ["N"] * 3 + ["Nm"] * 3,
        RATE_HZ * RATIO,
        point_unit="m",
        force_platforms=[plate],
    )
    return path


@pytest.fixture(scope="module")
def gait2392_markers() -> list[str]:
    return model_marker_names_of(GAIT2392, MARKER_SET)


@pytest.fixture(scope="module")
def walking5():
    return read_c3d(WALKING5), read_force_platforms(WALKING5)


# ---------------------------------------------------------------- presence


def _longest_interior_gap(present: np.ndarray) -> int:
    """Longest run of False between the first and last True, counted frame by frame."""
    idx = np.flatnonzero(present)
    best = run = 0
    for p in present[idx[0] : idx[-1] + 1]:
        run = 0 if p else run + 1
        best = max(best, run)
    return best


def test_marker_presence_of_walking5_matches_a_recount(walking5):
    rec, _ = walking5
    table = marker_presence(rec.marker_labels, rec.markers_m, rec.point_rate_hz, rec.first_frame)
    present = np.isfinite(rec.markers_m).all(axis=2)
    assert len(table) == 40 and list(table["label"]) == rec.marker_labels
    for j, row in enumerate(table.itertuples(index=False)):
        idx = np.flatnonzero(present[:, j])
        assert row.n_present == idx.size
        np.testing.assert_allclose(row.present_pct, 100.0 * idx.size / 1103, rtol=1e-12)
        assert (row.first_present_frame, row.last_present_frame) == (idx[0], idx[-1])
        assert row.longest_gap_frames == _longest_interior_gap(present[:, j])
        np.testing.assert_allclose(row.longest_gap_s, row.longest_gap_frames / 250.0, rtol=1e-12)
    assert table["first_present_frame"].min() == 57  # frames 0-56 hold no marker
    counts = present.sum(axis=1)
    np.testing.assert_array_equal(sparse_frames(rec.markers_m), np.flatnonzero(counts < 3))
    np.testing.assert_array_equal(sparse_frames(rec.markers_m, min_markers=1), np.arange(57))


def test_marker_presence_counts_file_frames_and_gaps():
    table = marker_presence(LABELS, _walker(), RATE_HZ, FIRST_FRAME).set_index("label")
    lkne, ltoe = table.loc["Subj:LKNE"], table.loc["Subj:LTOE"]
    assert (lkne.first_present_frame, lkne.last_present_frame, lkne.longest_gap_frames) == (38, 229, 10)
    np.testing.assert_allclose([lkne.present_pct, lkne.longest_gap_s], [91.0, 0.1], rtol=1e-12)
    assert (ltoe.first_present_frame, ltoe.last_present_frame, ltoe.longest_gap_frames) == (50, 219, 3)
    np.testing.assert_allclose(ltoe.present_pct, 100.0 * 167 / 200, rtol=1e-12)
    np.testing.assert_array_equal(sparse_frames(_walker(), FIRST_FRAME), np.arange(30, 38))
    never = marker_presence(["A"], np.full((4, 1, 3), np.nan), 100.0)
    assert never.loc[0, "n_present"] == 0 and never["first_present_frame"].isna().all()


# ---------------------------------------------------------------- lab axes and rotation


def test_axes_from_markers_alone_and_a_treadmill():
    W = _walker()
    v = vertical_axis(W)
    assert (v.axis, v.sign, v.basis) == (2, 1, "markers")
    w = walking_direction(W, RATE_HZ, 2)
    assert (w.axis, w.sign) == (0, 1)
    np.testing.assert_allclose(w.speed_m_per_s, SPEED_M_PER_S, rtol=0.02)
    treadmill = W.copy()
    treadmill[..., 0] -= SPEED_M_PER_S * np.arange(N_FRAMES)[:, None] / RATE_HZ
    assert walking_direction(treadmill, RATE_HZ, 2).axis is None
    upside_down = vertical_axis(-W[..., [0, 2, 1]])  # Y down
    assert (upside_down.axis, upside_down.sign) == (1, -1)


def test_walking5_summary(walking5):
    rec, plates = walking5
    s = inspect_c3d(WALKING5).summary
    assert (s.point_rate_hz, s.analog_rate_hz, s.first_frame, s.n_frames, s.point_unit) == (
        250.0,
        2000.0,
        0,
        1103,
        "mm",
    )
    np.testing.assert_allclose(s.duration_s, 1103 / 250.0, rtol=1e-12)
    assert (s.vertical.axis, s.vertical.sign, s.vertical.basis) == (2, 1, "force platforms")
    assert (s.vertical.marker_axis, s.vertical.marker_sign) == (2, 1)
    assert (s.walking.axis, s.walking.sign) == (0, -1)
    assert s.rotation_deg == (-90.0, 0.0, 0.0)
    assert s.rotation_forward_deg == (-90.0, 180.0, 0.0)
    assert [p.type for p in s.plates] == [2, 2]
    assert [p.corner_order for p in s.plates] == ["clockwise", "clockwise"]
    for summary, plate, unloaded_until_s in zip(s.plates, plates, (1.9, 2.3)):
        np.testing.assert_allclose(summary.normal, [0, 0, -1], atol=1e-9)
        fz = plate.force_n[:, 2]
        rest = np.median(fz[plate.time_s < unloaded_until_s])  # both plates are unloaded before 1.96 s, 2.37 s
        np.testing.assert_allclose(summary.rest_vertical_n, rest, atol=0.5)
        np.testing.assert_allclose(summary.peak_vertical_n, fz.max() - summary.rest_vertical_n, rtol=1e-12)
    np.testing.assert_allclose([p.rest_vertical_n for p in s.plates], [-14.2, -18.1], atol=0.3)
    assert s.analog_labels[:3] == ["Fx1", "Fy1", "Fz1"] and s.analog_units[3] == "Nmm"
    assert s.events.empty


def test_zup_file_summary(zup_file):
    s = inspect_c3d(zup_file).summary
    assert (s.first_frame, s.n_frames, s.point_unit) == (30, 200, "mm")
    np.testing.assert_allclose(s.first_time_s, 0.3, rtol=1e-12)
    assert (s.vertical.axis, s.vertical.sign) == (2, 1) and (s.walking.axis, s.walking.sign) == (0, 1)
    assert s.rotation_deg == s.rotation_forward_deg == (-90.0, 0.0, 0.0)
    (p,) = s.plates
    assert p.corner_order == "clockwise"
    np.testing.assert_allclose(p.normal, [0, 0, -1], atol=1e-9)
    np.testing.assert_allclose([p.rest_vertical_n, p.peak_vertical_n, p.peak_time_s], [-15.0, 800.0, 1.4], atol=1e-3)
    np.testing.assert_allclose(p.side_lengths_m, [0.6, 0.4], atol=1e-6)
    assert list(s.events["label"]) == ["Foot Strike", "Foot Off"]
    np.testing.assert_allclose(s.events["time_s"], [0.9, 1.25], atol=1e-6)
    np.testing.assert_array_equal(s.sparse_frames, np.arange(30, 38))
    assert s.n_empty_frames == 5


def test_yup_file_summary(yup_file):
    s = inspect_c3d(yup_file).summary
    assert s.point_unit == "m"
    assert (s.vertical.axis, s.vertical.sign, s.vertical.basis) == (1, 1, "force platforms")
    assert (s.walking.axis, s.walking.sign) == (0, 1)
    assert s.rotation_deg == s.rotation_forward_deg == (0.0, 0.0, 0.0)
    (p,) = s.plates
    assert p.corner_order == "counter-clockwise"
    np.testing.assert_allclose(p.normal, [0, 1, 0], atol=1e-9)
    np.testing.assert_allclose([p.rest_vertical_n, p.peak_vertical_n, p.peak_time_s], [-12.0, 800.0, 1.1], atol=1e-3)


# ---------------------------------------------------------------- label matching


def test_qtm_labels_match_gait2392_as_the_example_map_says(gait2392_markers):
    qtm = read_label_map(QTM_MAP)
    labels = [f"Subj:{k}" for k in qtm]
    m = match_labels(labels, gait2392_markers)
    assert {lab: mk for lab, mk, _ in m.pairs} == {
        f"Subj:{k}": v for k, v in qtm.items() if not any(c in k for c in ("TH", "SK", "FMT", "FB5"))
    }
    assert len(m.pairs) == 23 and not m.ambiguous
    assert len(m.unmatched_labels) == 16  # thigh and shank clusters, midfoot markers: lab-specific, left to the user
    assert set(m.unprovided_markers) == {v for k, v in qtm.items() if f"Subj:{k}" in m.unmatched_labels}


def test_walking5_labels_match_gait2392(walking5, gait2392_markers):
    rec, _ = walking5
    m = match_labels(rec.marker_labels, gait2392_markers)
    pairs = {lab: mk for lab, mk, _ in m.pairs}
    assert pairs == {
        "LASI": "L.ASIS",
        "RASI": "R.ASIS",
        "LCAL": "L.Heel",
        "RCAL": "R.Heel",
        "STRN": "Sternum",
        "LMT1": "L.Toe.Med",
        "RMT1": "R.Toe.Med",
        "LLFC": "L.Knee.Lat",
        "RLFC": "R.Knee.Lat",
        "LMFC": "L.Knee.Med",
        "RMFC": "R.Knee.Med",
        "LLMAL": "L.Ankle.Lat",
        "RLMAL": "R.Ankle.Lat",
        "LMMAL": "L.Ankle.Med",
        "RMMAL": "R.Ankle.Med",
    }
    assert len(m.unmatched_labels) == 25 and len(m.unprovided_markers) == 39 - 15
    assert heel_markers([mk for _, mk, _ in m.pairs]) == {"left": "L.Heel", "right": "R.Heel"}


@pytest.mark.skipif(not RAJAGOPAL.is_file(), reason="Rajagopal2016 copy not in tests/data")
def test_walking5_labels_match_rajagopal_by_name(walking5):
    rec, _ = walking5
    m = match_labels(rec.marker_labels, model_marker_names_of(RAJAGOPAL))
    assert len(m.pairs) == 34 and all(rule == "exact" for _, _, rule in m.pairs)
    assert m.unmatched_labels == ("T10", "RMT2", "RMT1", "LMT2", "LMT1", "STRN")
    assert starter_label_map(m).empty


# ---------------------------------------------------------------- outputs and the command


def test_snippet_without_a_map_file_holds_the_map_inline():
    text = config_snippet((-90.0, 0.0, 0.0), {"LASI": "L.ASIS", "a b": "x:y"}, {"left": "L.Heel", "right": "R.Heel"})
    doc = yaml.safe_load(text)
    assert doc == {
        "markers": {"lab_to_model_rotation_deg": [-90, 0, 0], "label_map": {"LASI": "L.ASIS", "a b": "x:y"}},
        "events": {"foot_markers": {"left": "L.Heel", "right": "R.Heel"}},
    }


def _merged(base: dict, over: dict) -> dict:
    out = dict(base)
    for key, value in over.items():
        out[key] = _merged(base.get(key, {}), value) if isinstance(value, dict) and key in base else value
    return out


def test_inspect_command_on_walking5(tmp_path, capsys, walking5):
    rec, _ = walking5
    map_tsv, snippet = tmp_path / "out" / "map.tsv", tmp_path / "out" / "snippet.yaml"
    code = main(
        [
            "inspect",
            str(WALKING5),
            "--model",
            str(GAIT2392),
            "--marker-set",
            str(MARKER_SET),
            "--label-map-out",
            str(map_tsv),
            "--config-out",
            str(snippet),
        ]
    )
    out = capsys.readouterr().out
    assert code == 0
    for needle in (
        "250 Hz, POINT:UNITS mm",
        "2000 Hz (8 samples per frame), 12 channel(s)",
        "frames    1103, first frame 0 (0-based) at 0.000 s",
        "duration 4.412 s",
        "frames with fewer than 3 markers: 153 of 1103",
        "57 of them without any marker",
        "resting (unloaded) vertical level -14.",
        "resting (unloaded) vertical level -18.",
        "corners listed clockwise seen from above",
        "vertical axis: +Z",
        "walking direction: -X",
        "lab_to_model_rotation_deg: [-90, 0, 0]",
        "walks toward model -X; [-90, 180, 0] also turns",
        "LASI  -> L.ASIS",
        "matched: 15 label(s)",
    ):
        assert needle in out, needle
    label_map = read_label_map(map_tsv)
    assert len(label_map) == 15 and label_map["LCAL"] == "L.Heel"
    names = model_marker_names(rec.marker_labels, label_map)
    assert {"L.Heel", "R.Heel", "L.ASIS", "R.ASIS"} <= set(names)
    doc = yaml.safe_load(snippet.read_text())
    assert doc["markers"] == {"lab_to_model_rotation_deg": [-90, 0, 0], "label_map": str(map_tsv)}
    assert doc["events"] == {"foot_markers": {"left": "L.Heel", "right": "R.Heel"}}
    assert doc["model"] == {"generic_model": str(GAIT2392)}
    base = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    check_config(_merged(base, doc), ROOT / "workflow" / "schemas" / "config.schema.yaml")
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".")]  # no staging left behind


def test_inspect_command_on_the_yup_file_without_a_model(yup_file, tmp_path, capsys):
    """Without a model the files choose a marker-set template; this file's eight markers fit none: the summary is
    printed, one line says what was and was not mapped, a starter map holds every label, and no config is written."""
    config = tmp_path / "lab" / "config.yaml"
    assert main(["inspect", str(yup_file), "--config-out", str(config)]) == 2
    captured = capsys.readouterr()
    assert "corners listed counter-clockwise seen from above" in captured.out and "vertical axis: +Y" in captured.out
    err = captured.err.strip()
    assert len(err.splitlines()) == 1
    assert "fit no marker-set template; closest: plugin_gait" in err and "8 of 12 required" in err
    assert "missing: LPSI or SACR, RPSI or SACR, LANK, RANK" in err and "left without a marker: HEAD" in err
    starter = pd.read_csv(tmp_path / "lab" / "label_map_starter.tsv", sep="\t", keep_default_na=False)
    assert starter.set_index("label")["marker"].to_dict() == {
        "LASI": "LASI", "RASI": "RASI", "LKNE": "LKNE", "RKNE": "RKNE", "LHEE": "LHEE", "RHEE": "RHEE",
        "LTOE": "LTOE", "RTOE": "RTOE", "HEAD": "",
    }  # fmt: skip
    assert not config.exists() and sorted(p.name for p in (tmp_path / "lab").iterdir()) == ["label_map_starter.tsv"]


def test_inspect_command_refuses_a_missing_file_and_a_map_without_model(tmp_path, capsys):
    missing = tmp_path / "nope.c3d"
    assert main(["inspect", str(missing)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(missing) in err
    assert main(["inspect", str(WALKING5), "--label-map-out", str(tmp_path / "m.tsv")]) == 2
    assert "--model" in capsys.readouterr().err
    assert not (tmp_path / "m.tsv").exists()


def test_plates_that_cannot_be_read_are_reported_not_fatal(tmp_path):
    """Moment channels declared in N·mm in a file in m: the plate reader refuses them, the inspection goes on."""
    path = tmp_path / "badplate.c3d"
    plate = ForcePlatform(
        2, [(1.3, 0.1, 0.0), (0.7, 0.1, 0.0), (0.7, 0.5, 0.0), (1.3, 0.5, 0.0)], (0, 0, -0.04), (1, 2, 3, 4, 5, 6)
    )
    write_c3d(
        path,
        LABELS,
        _walker(),
        RATE_HZ,
        CHANNELS,
        np.zeros((N_FRAMES * RATIO, 6)),
        ["N"] * 3 + ["Nmm"] * 3,
        RATE_HZ * RATIO,
        point_unit="m",
        force_platforms=[plate],
    )
    result = inspect_c3d(path)
    assert result.summary.plates == [] and "ANALOG:UNITS of channel 4" in result.summary.plate_problem
    assert "Force platforms: 1 declared, not readable" in result.text
    assert (result.summary.vertical.axis, result.summary.vertical.basis) == (2, "markers")
