"""motion/level_walking.py through the markers step and the strides summary: the clinical labs' level walks,
OpenSim's walking5 and Rajagopal2016's walk pass without a warning; a stair descent written with the project's
C3D writer (pelvis 0.95 m down, four plates a riser apart) is warned about with its figures before its speed."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.io.opensim_tables import read_markers
from loper_analysis.motion.level_walking import (
    MAX_PELVIS_CHANGE_M,
    level_walking_warning,
    pelvis_height_change_m,
)
from loper_analysis.motion.marker_names import model_marker_names
from loper_analysis.stages.markers.step import MarkerSettings, markers
from loper_analysis.stages.strides.step import TrialTables, strides_summary

DATA = Path(__file__).resolve().parents[1] / "data"
#: Each level walk's pelvis rise (+) or fall (-) (m) and its plates' height range (m; NaN: no plates), measured
#: with ezc3d 1.7 on the files as stored.
LEVEL_WALKS = {
    "c3d-parser/AUC/walk-nodevice.c3d": (-0.0046, 0.0018),
    "c3d-parser/FMC/walk-nodevice.c3d": (0.0075, 0.0),
    "c3d-parser/MH/walk-nodevice.c3d": (0.0154, 0.0),
    "c3d-parser/QCMAS/walk-nodevice.c3d": (-0.0002, 0.0),
    "c3d-parser/RBWH/walk-nodevice.c3d": (-0.0109, 0.0),
    "c3d-parser/RCH/walk-nodevice.c3d": (-0.0094, 0.0014),
    "c3d-parser/SYD/walk-nodevice.c3d": (0.0005, 0.0),
    "opensim-core/walking5.c3d": (-0.0057, 0.0),
}


@pytest.mark.parametrize("walk", sorted(LEVEL_WALKS))
def test_every_level_walk_passes_without_the_warning(walk, tmp_path, caplog):
    caplog.set_level(logging.WARNING)
    markers(DATA / walk, tmp_path / "w.trc", summary_out=tmp_path / "s.tsv")
    summary = pd.read_csv(tmp_path / "s.tsv", sep="\t", keep_default_na=False).iloc[0]
    change, plate_range = LEVEL_WALKS[walk]
    assert float(summary.pelvis_height_change_m) == pytest.approx(change, abs=1e-4)
    assert float(summary.plate_height_range_m) == pytest.approx(plate_range, abs=1e-4)
    assert summary.warnings == "" and "not level walking" not in caplog.text
    assert abs(change) < MAX_PELVIS_CHANGE_M / 4  # the limit stands 5x above the largest (MH, 15.4 mm)


def test_rajagopal2016s_walk_is_level():
    t, X, labels = read_markers(DATA / "rajagopal2016/Rajagopal_motion_capture_walk.trc")  # Y up
    change = pelvis_height_change_m(X, model_marker_names(labels), 1.0 / np.median(np.diff(t)), (0.0, 1.0, 0.0))
    assert change == pytest.approx(-0.0059, abs=1e-4)
    assert level_walking_warning(change, []) == ""


RATE_HZ, ANALOG_HZ = 100.0, 1000.0
#: A stair descent: 1 s on the landing, 0.95 m down over 2 s, 1 s at the bottom, walking toward the lab's -X.
DESCENT_M, SPEED_M_PER_S = 0.95, 1.2
#: Four plates one riser (0.17 m) below the other.
PLATE_HEIGHTS_M = (0.0, -0.17, -0.34, -0.51)


def _stair_descent(path: Path) -> Path:
    """A C3D of a subject walking down stairs over four plates at four heights (Z-up lab, m)."""
    t = np.arange(int(4 * RATE_HZ)) / RATE_HZ
    drop = -DESCENT_M * np.clip((t - 1.0) / 2.0, 0.0, 1.0)
    x = -SPEED_M_PER_S * t
    offsets = {
        "LASI": (0.05, 0.12, 1.0),
        "RASI": (0.05, -0.12, 1.0),
        "LPSI": (-0.10, 0.05, 1.02),
        "RPSI": (-0.10, -0.05, 1.02),
        "LHEE": (-0.05, 0.10, 0.08),
        "RHEE": (-0.05, -0.10, 0.08),
        "LTOE": (0.15, 0.10, 0.05),
        "RTOE": (0.15, -0.10, 0.05),
    }
    X = np.stack([np.column_stack([x - dx, np.full(t.size, dy), dz + drop]) for dx, dy, dz in offsets.values()], 1)
    plates = [
        ForcePlatform(
            2,
            ((-0.6 * k, 0.25, z), (-0.6 * k - 0.5, 0.25, z), (-0.6 * k - 0.5, -0.25, z), (-0.6 * k, -0.25, z)),
            (0.0, 0.0, -0.04),
            tuple(range(6 * k + 1, 6 * k + 7)),
        )
        for k, z in enumerate(PLATE_HEIGHTS_M)
    ]
    labels = [f"{q}{k + 1}" for k in range(4) for q in ("Fx", "Fy", "Fz", "Mx", "My", "Mz")]
    units = ["N", "N", "N", "Nmm", "Nmm", "Nmm"] * 4
    analogs = np.zeros((int(t.size * ANALOG_HZ / RATE_HZ), 24))
    return write_c3d(path, list(offsets), X, RATE_HZ, labels, analogs, units, ANALOG_HZ, force_platforms=plates)


EXPECTED = (
    "not level walking: the pelvis falls 0.950 m over the trial (more than 0.075 m, half a stair step); the force "
    "plates lie at different heights (0.000, -0.170, -0.340, -0.510 m; 0.510 m apart, more than 0.01 m)"
)


def test_a_stair_descent_is_warned_about_with_its_figures_before_its_speed(tmp_path, caplog):
    caplog.set_level(logging.INFO)
    c3d = _stair_descent(tmp_path / "stairs.c3d")
    markers(c3d, tmp_path / "w.trc", settings=MarkerSettings(cutoff_hz=None), summary_out=tmp_path / "m.tsv")
    summary = pd.read_csv(tmp_path / "m.tsv", sep="\t", keep_default_na=False).iloc[0]
    assert float(summary.pelvis_height_change_m) == pytest.approx(-DESCENT_M, abs=1e-5)  # float32 mm
    assert float(summary.plate_height_range_m) == pytest.approx(0.51, abs=1e-6)
    assert summary.warnings == EXPECTED
    assert summary.speed_m_per_s == pytest.approx(SPEED_M_PER_S, abs=1e-3)
    said = [r.getMessage() for r in caplog.records]
    level = next(i for i, m in enumerate(said) if "not level walking" in m)
    speed = next(i for i, m in enumerate(said) if "at 1.20 m/s" in m)  # turned 180 deg to walk along +X
    assert said[level] == f"{c3d}: {EXPECTED}" and level < speed
    assert caplog.records[level].levelno == logging.WARNING

    # the strides summary: the trial's warning first, next to its speed
    stride_table = tmp_path / "strides.tsv"
    stride_table.write_text("removed\treason\tduration_s\n")  # no strides: the header only
    ik = tmp_path / "ik.tsv"
    ik.write_text(
        "n_frames\tn_frames_left_out\tmarker_rms_mean_m\tworst_marker\tworst_marker_rms_m\tmarker_geometry_change\t"
        "warnings\n400\t0\t0.01\tLTOE\t0.02\t0.01\tpoor fit\n"
    )
    table = strides_summary(
        [("S01", "stairs")],
        [stride_table],
        tmp_path / "summary.tsv",
        files=TrialTables(ik=[ik], markers=[tmp_path / "m.tsv"]),
    )
    assert table["warnings"].tolist() == [f"{EXPECTED} | poor fit"]
    assert table["speed_m_per_s"].iloc[0] == pytest.approx(SPEED_M_PER_S, abs=1e-3)
    written = pd.read_csv(tmp_path / "summary.tsv", sep="\t", keep_default_na=False)
    assert written["warnings"].tolist() == [f"{EXPECTED} | poor fit"]


def test_limits_sit_at_their_figures():
    assert level_walking_warning(-0.075, [0.0, 0.01]) == ""  # at both limits: level
    assert level_walking_warning(0.0751, []) == (
        "not level walking: the pelvis rises 0.075 m over the trial (more than 0.075 m, half a stair step)"
    )
    assert level_walking_warning(float("nan"), [0.0, 0.0101]).startswith(
        "not level walking: the force plates lie at different heights (0.000, 0.010 m; 0.010 m apart"
    )
