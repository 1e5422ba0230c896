"""The stillest window of a static trial (loper_analysis.motion.still_window): each marker's motion over a window,
the window where the measurement markers move least, and the stop when none stays within the limit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import read_c3d
from loper_analysis.motion.static_trial import scale_window_s
from loper_analysis.motion.still_window import stillest_window_s

#: A clinical lab's 11-s static trial in which the subject is not still all the time (README of tests/data/c3d-parser).
RBWH_STATIC = Path(__file__).resolve().parents[1] / "data" / "c3d-parser" / "RBWH" / "static.c3d"
#: The markers the Plug-in Gait scale setup measures between (pelvis width, trunk, thighs, shanks, feet).
RBWH_MEASURED = ["RASI", "LASI", "CLAV", "RKNE", "LKNE", "RANK", "LANK", "RHEE", "RTOE", "LHEE", "LTOE"]


def _circling(t, radius_m, moving=(0, 1, 2)):
    """Three markers standing apart, those of ``moving`` circling (period 0.1 s) with ``radius_m`` (m) at each
    time: RMS motion ``radius_m`` about the mean over whole periods."""
    angle = 2 * np.pi * t / 0.1
    X = np.tile(np.array([[0.0, 1.0, 0.1], [0.0, 0.5, 0.1], [0.2, 0.05, 0.1]]), (t.size, 1, 1))
    circle = np.asarray(radius_m)[:, None] * np.column_stack([np.cos(angle), np.sin(angle), 0 * angle])
    X[:, list(moving)] += circle[:, None, :]
    return X


def test_the_stillest_window_lies_where_the_markers_stand_still():
    t = np.arange(500) / 100.0
    still = (t >= 2.0 - 1e-9) & (t <= 3.0 + 1e-9)
    X = _circling(t, np.where(still, 0.0, 0.02))  # 20 mm of motion but in [2, 3] s
    window = scale_window_s(t, [(-1, -1)], 0.5, markers_m=X, labels=["ASIS", "KNEE", "TOE"])
    assert window == (t[200], t[249])  # every window inside [2, 3] s is still: the earliest
    got = stillest_window_s(t, X, ["ASIS", "KNEE", "TOE"], 0.5, max_motion_rms_m=0.005)
    assert got.window_s == window and got.n_windows == 451
    assert max(got.motion_rms_m.values()) == pytest.approx(0.0, abs=1e-15)
    # the same input, the same window; a still trial: its first window, as without markers
    assert scale_window_s(t, (), 0.5, markers_m=X, labels=["ASIS", "KNEE", "TOE"]) == window
    X0 = _circling(t, np.zeros(t.size))
    assert scale_window_s(t, (), 0.5, markers_m=X0, labels=["ASIS", "KNEE", "TOE"]) == scale_window_s(t, (), 0.5)
    # a range set is kept (only checked), a trial shorter than the window is taken whole
    assert scale_window_s(t, [(0.0, 0.5)], 0.5, markers_m=X, labels=["ASIS", "KNEE", "TOE"]) == (0.0, 0.5)
    assert scale_window_s(t[:40], (), 0.5, markers_m=X[:40], labels=["ASIS", "KNEE", "TOE"]) == (0.0, 0.39)
    # a measurement marker hidden throughout [2, 3] s: not that window
    X[200:301, 1] = np.nan
    got = stillest_window_s(t, X, ["ASIS", "KNEE", "TOE"], 0.5, needed=["KNEE"])
    assert not (got.window_s[1] < 2.0 or got.window_s[0] > 3.0)  # it holds some of [2, 3] s, and the knee
    assert got.motion_rms_m["KNEE"] < 0.02


def test_within_the_limit_the_measurement_markers_choose_the_window():
    """The measured knee is still in [3, 4] s (10 mm elsewhere); the toe (not measured) moves 20 mm there only."""
    t = np.arange(600) / 100.0
    in_34 = (t >= 3.0 - 1e-9) & (t <= 4.0 + 1e-9)
    X = _circling(t, np.where(in_34, 0.0, 0.01))
    X[:, 2] = _circling(t, np.where(in_34, 0.02, 0.0))[:, 2]
    labels = ["ASIS", "KNEE", "TOE"]
    got = stillest_window_s(t, X, labels, 1.0, needed=["ASIS", "KNEE"], max_motion_rms_m=0.05)
    assert got.window_s == (3.0, 3.99) and got.scored == ["ASIS", "KNEE"]
    assert got.motion_rms_m["KNEE"] == pytest.approx(0.0, abs=1e-12)
    assert got.motion_rms_m["TOE"] == pytest.approx(0.02, rel=1e-9)
    # a limit of 15 mm: [3, 4] s is out (the toe); the knee moves least in the earliest second reaching furthest
    # into it with the toe within 15 mm: 56 of its 100 frames there, toe about sqrt(0.56) 20 mm = 15.0 mm, knee
    # about sqrt(0.44) 10 mm = 6.6 mm
    got = stillest_window_s(t, X, labels, 1.0, needed=["ASIS", "KNEE"], max_motion_rms_m=0.015)
    assert got.window_s == (2.56, 3.55)
    assert got.motion_rms_m["TOE"] <= 0.015 and got.motion_rms_m["KNEE"] == pytest.approx(0.0066, abs=2e-4)
    # brute force: every window with all markers within 15 mm has the knee moving at least as much
    for start in range(501):
        m = [_rms_m(X[start : start + 100, j]) for j in range(3)]
        if max(m) <= 0.015:
            assert m[1] >= got.motion_rms_m["KNEE"] - 1e-9 and (m[1] > got.motion_rms_m["KNEE"] or start >= 256)


def test_a_trial_with_no_still_window_stops_naming_the_stillest():
    """The toe (not measured) circles 100 mm everywhere but 60 mm in [2, 3) s: the second from 2 s moves 60 mm,
    any other more."""
    t = np.arange(600) / 100.0
    X = _circling(t, np.where((t >= 2.0 - 1e-9) & (t < 3.0 - 1e-9), 0.06, 0.1), moving=[2])
    with pytest.raises(
        LoperInputError,
        match=r"^static\.trc: the subject does not stand still in the scaling window 2\.0000 \.\. 2\.9900 s of the "
        r"static trial: marker\(s\) 'Subject:RTOE' \(model marker TOE\) 60 mm move more than "
        r"model\.static_max_motion_rms_m 0\.05 m RMS about their mean; it is the stillest 1 s "
        r"\(model\.static_duration_s\) of the static trial \(0\.0000 \.\. 5\.9900 s, 501 windows compared\): set "
        r"a time range where the subject stands still \(time_range of scale_setup\.xml\), a shorter "
        r"model\.static_duration_s or a larger model\.static_max_motion_rms_m$",
    ):
        scale_window_s(
            t,
            [(-1, -1)],
            1.0,
            "static.trc",
            "time_range of scale_setup.xml",
            markers_m=X,
            labels=["ASIS", "KNEE", "TOE"],
            needed=["KNEE"],
            max_motion_rms_m=0.05,
            lab_labels={"TOE": "Subject:RTOE"},
        )
    # a larger limit takes it
    assert scale_window_s(t, (), 1.0, markers_m=X, labels=["ASIS", "KNEE", "TOE"], max_motion_rms_m=0.07) == (
        2.0,
        2.99,
    )


def _rms_m(points_m):
    """RMS distance (m) of (n, 3) points from their mean, written out."""
    d = points_m - points_m.mean(axis=0)
    return float(np.sqrt(np.mean(d[:, 0] ** 2 + d[:, 1] ** 2 + d[:, 2] ** 2)))


def test_the_stillest_second_of_a_lab_static_in_which_the_subject_moves():
    rec = read_c3d(RBWH_STATIC)
    t, X, labels = rec.time_s, rec.markers_m, list(rec.marker_labels)
    assert X.shape == (1102, 25, 3) and np.isfinite(X).all()
    measured = [labels.index(m) for m in RBWH_MEASURED]

    def motion(start):  # every marker's RMS motion over the 100 frames from ``start``, m
        return np.array([_rms_m(X[start : start + 100, j]) for j in range(len(labels))])

    # the first second (the window before): the trunk moves 120 mm, over the 50-mm limit
    assert motion(0).max() == pytest.approx(0.1198, abs=5e-4) and labels[int(motion(0).argmax())] == "CLAV"
    window = scale_window_s(t, [(-1, -1)], 1.0, markers_m=X, labels=labels, needed=RBWH_MEASURED, max_motion_rms_m=0.05)
    assert window == (2.15, 3.14)
    start = int(np.flatnonzero(t == window[0])[0])
    chosen = motion(start)
    assert chosen.max() < 0.05  # every marker still: at most 7.8 mm (LMKN), the measured ones 6.6 mm (LKNE)
    assert chosen.max() == pytest.approx(0.0078, abs=1e-4) and chosen[measured].max() == pytest.approx(0.0066, abs=1e-4)
    # brute force over every start frame: no window within the limit whose measured markers move less
    for s in range(0, 1003):
        m = motion(s)
        if m.max() <= 0.05:
            assert m[measured].max() >= chosen[measured].max() - 1e-9, t[s]
    # and a few by name: the next still seconds and the stepping at the end
    assert motion(763).max() == pytest.approx(0.0069, abs=1e-4) and motion(763)[measured].max() > chosen[measured].max()
    assert motion(1000).max() > 0.3
    # a tighter limit than any second holds stops, naming the stillest second of all markers, 7.63 .. 8.62 s
    with pytest.raises(LoperInputError, match=r"scaling window 7\.6300 \.\. 8\.6200 s .* 'RASI' 7 mm.* stillest 1 s"):
        scale_window_s(t, (), 1.0, markers_m=X, labels=labels, needed=RBWH_MEASURED, max_motion_rms_m=0.005)
    assert min(motion(s).max() for s in range(1003)) == pytest.approx(motion(763).max(), abs=1e-12)
