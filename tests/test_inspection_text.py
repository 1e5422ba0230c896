"""inspection_text.py: what ``loper-analysis inspect`` prints, line by line, for a recording whose every number is
known by construction and for a known label match."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.inspection_text import format_label_match, format_summary
from loper_analysis.io.c3d_writer import ForcePlatform, write_c3d
from loper_analysis.motion.label_matching import match_labels
from loper_analysis.stages.inspect import inspect_c3d

RATE_HZ, N_FRAMES, FIRST_FRAME = 100.0, 100, 10
LABELS = ["S:HEAD", "S:LASI", "S:RASI", "S:LHEE", "S:RHEE"]


@pytest.fixture(scope="module")
def text(tmp_path_factory) -> str:
    """A Z-up lab walking +X at 1 m/s, frames 0-2 empty, LHEE missing 40-44; one plate (corners clockwise seen
    from above, so its Fz channel is minus the upward force) resting at -10 N with a 600 N half sine from 0.3 to
    0.7 s of analog time; one event at 0.45 s."""
    t = np.arange(N_FRAMES) / RATE_HZ
    rows = [(0, 0, 1.7), (0.05, 0.12, 0.95), (0.05, -0.12, 0.95), (-0.05, 0.1, 0.05), (-0.05, -0.1, 0.05)]
    X = np.zeros((N_FRAMES, len(rows), 3))
    for j, (fwd, left, up) in enumerate(rows):
        X[:, j] = np.column_stack([0.2 + 1.0 * t + fwd, np.full(N_FRAMES, left), np.full(N_FRAMES, up)])
    X[:3] = np.nan
    X[40:45, 3] = np.nan
    ta = np.arange(N_FRAMES * 10) / 1000.0
    channels = np.zeros((N_FRAMES * 10, 6))
    channels[:, 2] = -(np.where((ta >= 0.3) & (ta <= 0.7), 600 * np.sin(np.pi * (ta - 0.3) / 0.4), 0.0) - 10.0)
    plate = ForcePlatform(
        2, [(1.3, 0.1, 0.0), (0.7, 0.1, 0.0), (0.7, 0.5, 0.0), (1.3, 0.5, 0.0)], (0, 0, -0.04), (1, 2, 3, 4, 5, 6)
    )
    path = tmp_path_factory.mktemp("inspect") / "s.c3d"
    write_c3d(
        path,
        LABELS,
        X,
        RATE_HZ,
        ["Fx1", "Fy1", "Fz1", "Mx1", "My1", "Mz1"],
        channels,
        ["N"] * 3 + ["Nmm"] * 3,
        1000.0,
        first_frame=FIRST_FRAME,
        force_platforms=[plate],
        events=[("Left", "Foot Strike", 0.45)],
    )
    return format_summary(inspect_c3d(path).summary)


def test_header_and_markers(text):
    lines = text.splitlines()
    assert lines[1:4] == [
        "  markers   100 Hz, POINT:UNITS mm (shown below in m)",
        "  analogs   1000 Hz (10 samples per frame), 6 channel(s)",
        "  frames    100, first frame 10 (0-based) at 0.100 s, last frame 109 at 1.090 s; duration 1.000 s "
        "(100 frames / 100 Hz)",
    ]
    assert "  S:HEAD       97.0     13    109  none" in lines  # frames 10-12 empty
    assert "  S:LHEE       92.0     13    109  5 frames (0.050 s)" in lines
    assert (
        "  frames with fewer than 3 markers: 3 of 100 (frames 10-12; 3 of them without any marker; inverse "
        "kinematics cannot use them)" in lines
    )


def test_plate_lines(text):
    lines = text.splitlines()
    assert "Force platforms: 1 (forces on the body, lab frame; vertical = +Z)" in lines
    assert "    size 0.600 x 0.400 m, centre (1.000, 0.300, 0.000) m" in lines
    assert (
        "    normal from the corners (right-hand rule of their order): (0.000, 0.000, -1.000): corners listed "
        "clockwise seen from above" in lines
    )
    # loaded where 600 sin > 20 N: 0.4 s * (1 - 2 asin(1/30) / pi) of the 1 s = 39.1 %
    assert "    resting (unloaded) vertical level -10.0 N; loaded (> 20 N above it) 39.1 % of the time" in lines
    # the peak at 0.5 s of analog time, plus the first frame's 0.1 s
    assert "    peak vertical force 600.0 N above rest at 0.600 s (590.0 N as read)" in lines
    assert "    3  Fz1  N         plate 1 Fz" in lines and "    6  Mz1  Nmm       plate 1 Mz" in lines


def test_events_and_lab_frame(text):
    lines = text.splitlines()
    assert "  Left     Foot Strike         0.450 s  (frame 45)" in lines
    assert (
        "  vertical axis: +Z (from the force platforms); the markers agree (median spread of a frame's markers, m: "
        "X 0.10, Y 0.24, Z 1.65)" in lines
    )
    # 97 frames present: 96 steps of 10 ms at 1 m/s
    assert "  walking direction: +X (the markers travel +0.96 m along X at 1.00 m/s)" in lines
    assert (
        "  suggested markers.lab_to_model_rotation_deg: [-90, 0, 0] (degrees about the fixed X, Y, Z: up -> model +Y)"
        in lines
    )
    assert lines[-1] == "  (this trial then walks toward model +X, OpenSim's forward)"


def test_label_match_text():
    m = match_labels(["S:LASI", "S:RHEE", "S:LHEE", "S:LCAL", "S:C7"], ["L.ASIS", "R.Heel", "L.Heel", "Sternum"])
    assert format_label_match(m, "gait2392", 4) == (
        "Labels and model markers (gait2392: 4 markers)\n"
        "  matched: 2 label(s)\n"
        "    S:LASI -> L.ASIS               (synonym)\n"
        "    S:RHEE -> R.Heel               (synonym)\n"
        "  ambiguous (left unmatched): 2\n"
        "    S:LHEE: L.Heel (wanted by more than one label)\n"
        "    S:LCAL: L.Heel (wanted by more than one label)\n"
        "  labels without a model marker: 3\n"
        "    S:LHEE, S:LCAL, S:C7\n"
        "  model markers no label provides: 2\n"
        "    L.Heel, Sternum\n"
    )
    m = match_labels(["LANK"], ["L.Ankle", "L.Ankle.Lat"])
    assert "    LANK: L.Ankle or L.Ankle.Lat\n" in format_label_match(m, "m", 2)
