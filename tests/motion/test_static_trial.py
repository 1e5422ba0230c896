"""The static trial as scaling uses it (loper_analysis.motion.static_trial): the window and the pose over it."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.static_trial import scale_window_s, static_pose, time_range_is_set

T = 7.8125 + np.arange(200) / 100.0  # a file whose first frame is not at 0 s


def test_the_setups_time_range_wins_and_unset_ranges_are_ignored():
    assert time_range_is_set((0.0, 0.1)) and not time_range_is_set((-1.0, -1.0)) and not time_range_is_set((1, 0))
    assert scale_window_s(T, [(8.0, 8.5)], duration_s=1.0) == (T[19], T[68])  # the frames inside it
    # model scaler and marker placer with their own ranges: the window spans both
    assert scale_window_s(T, [(8.0, 8.2), (8.3, 8.6), (-1, -1)]) == (T[19], T[78])
    assert scale_window_s(T, [(-1, -1)], duration_s=1.0) == (T[0], T[99])  # the first second
    assert scale_window_s(T, [None]) == (T[0], T[-1])  # the whole trial


def test_a_range_outside_the_trial_names_it_the_trial_and_the_setting():
    with pytest.raises(
        LoperInputError,
        match=r"s\.trc: time_range of lab\.xml 0 \.\. 1 s holds no frame of the static "
        r"trial \(7\.8125 \.\. 9\.8025 s, the file's clock\)",
    ):
        scale_window_s(T, [(0.0, 1.0)], source="s.trc", setting="time_range of lab.xml")


def _markers():
    X = np.tile(np.array([[0.0, 1.0, 0.1], [0.0, 0.5, 0.1], [0.2, 0.05, 0.1]]), (10, 1, 1))
    X += 0.001 * np.arange(10)[:, None, None]  # sway: each frame 1 mm further
    return np.arange(10) / 100.0, X


def test_each_marker_is_averaged_over_the_frames_where_it_is_present():
    t, X = _markers()
    X[:4, 1] = np.nan  # knee hidden in the first 4 frames
    X[7, 2] = np.nan
    pose = static_pose(t, X, ["ASIS", "KNEE", "TOE"], window_s=(0.0, 0.09), needed=["ASIS", "KNEE"])
    assert pose.n_filled == {"KNEE": 4, "TOE": 1} and pose.left_out == [] and not np.isnan(pose.markers_m).any()
    np.testing.assert_allclose(pose.markers_m.mean(axis=0)[1], np.nanmean(X[:, 1], axis=0), rtol=1e-15)
    np.testing.assert_allclose(pose.markers_m[:4, 1], np.tile(np.nanmean(X[4:, 1], axis=0), (4, 1)), rtol=1e-15)
    np.testing.assert_array_equal(pose.markers_m[4:, 1], X[4:, 1])  # present frames unchanged


def test_a_marker_absent_from_the_window_stops_if_needed_and_is_left_out_otherwise():
    t, X = _markers()
    X[:6, 1] = np.nan
    X[:, 2] = np.nan
    with pytest.raises(
        LoperInputError,
        match=r"static\.trc: marker\(s\) 'Subject:RKNE' \(model marker KNEE\) missing "
        r"in every frame of the scaling window 0\.0000 \.\. 0\.0500 s \(6 frames\)"
        r".*scale_setup\.xml",
    ):
        static_pose(
            t,
            X,
            ["ASIS", "KNEE", "TOE"],
            window_s=(0.0, 0.05),
            needed=["KNEE"],
            lab_labels={"KNEE": "Subject:RKNE"},
            source="static.trc",
            setting="time_range of scale_setup.xml",
        )
    pose = static_pose(t, X, ["ASIS", "KNEE", "TOE"], window_s=(0.06, 0.09), needed=["KNEE"])
    assert pose.labels == ["ASIS", "KNEE"] and pose.left_out == ["TOE"] and pose.markers_m.shape == (4, 2, 3)


def test_marker_motion_is_the_rms_distance_from_the_mean_and_a_moving_subject_stops():
    t = np.arange(10) / 100.0
    X = np.tile(np.array([[0.0, 1.0, 0.1], [0.0, 0.5, 0.1], [0.2, 0.05, 0.1]]), (10, 1, 1))
    angle = 2 * np.pi * np.arange(10) / 10  # the toe marker circles a radius of 30 mm: RMS motion 30 mm exactly
    X[:, 2] += 0.03 * np.column_stack([np.cos(angle), np.sin(angle), 0 * angle])
    X[3, 2] = np.nan  # an absent frame does not count: the RMS is over the 9 present points
    pose = static_pose(t, X, ["ASIS", "KNEE", "TOE"], window_s=(0.0, 0.09))
    present = np.delete(X[:, 2], 3, axis=0)
    expected = np.sqrt(np.mean(np.sum((present - present.mean(axis=0)) ** 2, axis=1)))
    assert pose.motion_rms_m["TOE"] == pytest.approx(expected, rel=1e-12) and 0.029 < expected < 0.031
    assert pose.motion_rms_m["ASIS"] == pytest.approx(0.0, abs=1e-15)  # a still marker
    assert static_pose(
        t, X, ["ASIS", "KNEE", "TOE"], window_s=(0.0, 0.09), max_motion_rms_m=0.031
    ).labels  # under the limit
    with pytest.raises(
        LoperInputError,
        match=r"static\.trc: the subject does not stand still in the scaling window "
        r"0\.0000 \.\. 0\.0900 s of the static trial: marker\(s\) 'Subject:RTOE' "
        r"\(model marker TOE\) 30 mm move more than model\.static_max_motion_rms_m "
        r"0\.02 m RMS",
    ):
        static_pose(
            t,
            X,
            ["ASIS", "KNEE", "TOE"],
            window_s=(0.0, 0.09),
            lab_labels={"TOE": "Subject:RTOE"},
            source="static.trc",
            max_motion_rms_m=0.02,
        )
