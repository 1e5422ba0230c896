"""Marker processing: cubic-spline gap filling and the lab-to-model rotation."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.markers import (
    GAP_REPORT_COLUMNS,
    GAP_SUMMARY_COLUMNS,
    fill_gaps,
    gap_summary,
    require_markers_per_frame,
    rotate_markers,
)

FS = 128.0
N = 256
SOURCE = "data/raw/S01/walk01.c3d"


#: Seed of the ``rng`` fixture (tests/conftest.py) in this module.
RNG_SEED = 7


def cubic_marker(t):
    """A trajectory (n, 3) in m that is a cubic polynomial of time in every coordinate."""
    return np.column_stack(
        [
            0.3 + 1.2 * t - 0.4 * t**2 + 0.05 * t**3,
            0.9 - 0.02 * t**3,
            -0.1 + 0.2 * t + 0.03 * t**2,
        ]
    )


def sinusoid_marker(t, f_hz=1.0, amplitude_m=0.1):
    w = 2 * np.pi * f_hz
    return np.column_stack([amplitude_m * np.sin(w * t), 0.05 * np.cos(w * t) + 0.9, 0.2 + 0 * t])


@pytest.fixture
def trial():
    t = np.arange(N) / FS
    return np.stack([cubic_marker(t), sinusoid_marker(t)], axis=1)  # (N, 2, 3)


def test_cubic_trajectory_comes_back_exactly(trial):
    gappy = trial.copy()
    gappy[40:50, 0] = np.nan
    gappy[100, 0, 1] = np.nan  # one coordinate missing = the whole point is refilled
    gappy[200:203, 0] = np.nan
    filled, report = fill_gaps(gappy, 10, ["CUB", "SIN"], SOURCE)
    np.testing.assert_allclose(filled[:, 0], trial[:, 0], rtol=0, atol=1e-12)
    assert list(report.columns) == list(GAP_REPORT_COLUMNS)
    assert report.to_dict("records") == [
        {"marker": "CUB", "first_frame": 40, "last_frame": 49, "n_frames": 10},
        {"marker": "CUB", "first_frame": 100, "last_frame": 100, "n_frames": 1},
        {"marker": "CUB", "first_frame": 200, "last_frame": 202, "n_frames": 3},
    ]


def test_sinusoid_is_filled_within_a_tenth_of_a_millimetre(trial):
    # A 10-frame gap at 128 Hz spans H = 11/128 s; the cubic interpolation
    # error is of order H^4 max|x''''| / 384 = 0.1 m (2 pi)^4 H^4 / 384 = 2e-5 m.
    gappy = trial.copy()
    gappy[60:70, 1] = np.nan
    filled, report = fill_gaps(gappy, 10, ["CUB", "SIN"], SOURCE)
    error = np.abs(filled[60:70, 1] - trial[60:70, 1]).max()
    assert error < 1e-4
    assert error > 0  # a sinusoid is not a cubic: the fill is an approximation
    np.testing.assert_array_equal(filled[:60, 1], trial[:60, 1])  # valid frames untouched
    assert report.to_dict("records") == [{"marker": "SIN", "first_frame": 60, "last_frame": 69, "n_frames": 10}]


def test_input_is_not_modified_and_complete_markers_give_an_empty_report(trial):
    gappy = trial.copy()
    gappy[5, 1] = np.nan
    before = gappy.copy()
    filled, _ = fill_gaps(gappy, 3, ["CUB", "SIN"], SOURCE)
    np.testing.assert_array_equal(gappy, before)
    assert not np.isnan(filled).any()
    same, report = fill_gaps(trial, 0, ["CUB", "SIN"], SOURCE)
    np.testing.assert_array_equal(same, trial)
    assert same is not trial
    assert len(report) == 0 and list(report.columns) == list(GAP_REPORT_COLUMNS)


def test_gap_of_exactly_the_limit_is_filled_one_more_is_refused(trial):
    gappy = trial.copy()
    gappy[30:35, 0] = np.nan
    _, report = fill_gaps(gappy, 5, ["CUB", "SIN"], SOURCE)
    assert report.n_frames.tolist() == [5]
    with pytest.raises(LoperInputError) as err:
        fill_gaps(gappy, 4, ["CUB", "SIN"], SOURCE)
    assert "frames 30..34: a gap of 5 frames exceeds the limit of 4 frames" in str(err.value)


def test_long_gap_error_names_file_marker_and_frames(trial):
    gappy = trial.copy()
    gappy[100:125, 1] = np.nan
    with pytest.raises(LoperInputError) as err:
        fill_gaps(gappy, 12, ["CUB", "SIN"], SOURCE)
    message = str(err.value)
    assert message.startswith(f"{SOURCE}: cannot fill marker gaps")
    assert "marker SIN is missing in frames 100..124: a gap of 25 frames exceeds the limit of 12 frames" in message
    assert "CUB" not in message


@pytest.mark.parametrize(
    "frames, edge, text",
    [
        (slice(0, 3), "start", "frames 0..2 (3 frames) at the start of the trial"),
        (slice(N - 1, N), "end", f"frames {N - 1}..{N - 1} (1 frame) at the end of the trial"),
    ],
)
def test_gap_at_an_edge_cannot_be_interpolated(trial, frames, edge, text):
    gappy = trial.copy()
    gappy[frames, 0] = np.nan
    with pytest.raises(LoperInputError) as err:
        fill_gaps(gappy, 50, ["CUB", "SIN"], SOURCE)
    message = str(err.value)
    assert SOURCE in message and f"marker CUB is missing in {text}" in message
    assert "cannot be interpolated; trim the trial" in message


def test_every_problem_is_listed(trial):
    gappy = trial.copy()
    gappy[:, 0] = np.nan
    gappy[10:40, 1] = np.nan
    with pytest.raises(LoperInputError) as err:
        fill_gaps(gappy, 5, ["CUB", "SIN"], SOURCE)
    message = str(err.value)
    assert f"marker CUB is missing in every frame (0..{N - 1})" in message
    assert "marker SIN is missing in frames 10..39: a gap of 30 frames exceeds the limit of 5 frames" in message


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(max_gap_frames=-1), "max_gap_frames must be an integer >= 0, got -1"),
        (dict(max_gap_frames=2.5), "max_gap_frames must be an integer >= 0, got 2.5"),
        (dict(labels=["CUB"]), "labels must name 2 markers, got 1"),
    ],
)
def test_fill_gaps_checks_its_arguments(trial, kwargs, match):
    args = dict(markers_m=trial, max_gap_frames=3, labels=["CUB", "SIN"], source=SOURCE)
    with pytest.raises(LoperInputError, match=match):
        fill_gaps(**{**args, **kwargs})


def test_fill_gaps_refuses_infinite_values(trial):
    bad = trial.copy()
    bad[7, 1, 2] = np.inf
    with pytest.raises(LoperInputError, match="infinite at frame 7, marker index 1"):
        fill_gaps(bad, 3, ["CUB", "SIN"], SOURCE)


# ---------------------------------------------------------------- rotation


def test_minus_90_about_x_turns_z_up_into_y_up():
    np.testing.assert_allclose(rotate_markers(np.array([1.0, 2.0, 3.0]), (-90, 0, 0)), [1.0, 3.0, -2.0], atol=1e-15)


@pytest.mark.parametrize(
    "angles, point, expected",
    [
        ((0, 0, 90), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)),  # counter-clockwise about Z
        ((0, 90, 0), (0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),  # counter-clockwise about Y
        ((90, 90, 0), (0.0, 1.0, 0.0), (1.0, 0.0, 0.0)),  # X first (y -> z), then Y (z -> x)
        ((90, 90, 0), (1.0, 0.0, 0.0), (0.0, 0.0, -1.0)),  # about fixed axes: X leaves x, then Y takes x -> -z
    ],
)
def test_rotations_about_fixed_axes_in_order_x_y_z(angles, point, expected):
    np.testing.assert_allclose(rotate_markers(np.array(point), angles), expected, atol=1e-15)


def test_rotation_keeps_shape_distances_and_nan(rng):
    X = rng.normal(size=(20, 4, 3))
    X[3, 2] = np.nan
    Y = rotate_markers(X, (-90, 10, 35))
    assert Y.shape == X.shape
    assert np.isnan(Y[3, 2]).all() and np.isnan(Y).sum() == 3
    np.testing.assert_allclose(np.linalg.norm(Y[5, 0] - Y[5, 1]), np.linalg.norm(X[5, 0] - X[5, 1]), rtol=1e-14)
    # the inverse of Rz Ry Rx is Rx^-1 Ry^-1 Rz^-1: undo Z, then Y, then X
    back = rotate_markers(rotate_markers(rotate_markers(Y, (0, 0, -35)), (0, -10, 0)), (90, 0, 0))
    np.testing.assert_allclose(back, X, atol=1e-14)


@pytest.mark.parametrize(
    "markers, angles, match",
    [
        (np.zeros((5, 2)), (0, 0, 0), r"shape \(\.\.\., 3\)"),
        (np.zeros((5, 3)), (0, 0), "3 finite angles"),
        (np.zeros((5, 3)), (0, np.nan, 0), "3 finite angles"),
    ],
)
def test_rotation_checks_its_arguments(markers, angles, match):
    with pytest.raises(LoperInputError, match=match):
        rotate_markers(markers, angles)


# ---------------------------------------------------------------- gaps left missing (real recordings)


def test_keep_fills_short_interior_gaps_and_leaves_the_rest_missing(trial):
    gappy = trial.copy()
    gappy[:4, 0] = np.nan  # start of the trial
    gappy[40:45, 0] = np.nan  # 5 frames: filled
    gappy[100:130, 0] = np.nan  # 30 frames: too long
    gappy[N - 2 :, 1] = np.nan  # end of the trial
    filled, report = fill_gaps(gappy, 5, ["CUB", "SIN"], SOURCE, unfillable="keep")
    np.testing.assert_allclose(filled[40:45, 0], trial[40:45, 0], rtol=0, atol=1e-12)  # a cubic comes back
    assert np.isnan(filled[:4, 0]).all() and np.isnan(filled[100:130, 0]).all() and np.isnan(filled[N - 2 :, 1]).all()
    assert np.isnan(filled).any(axis=2).sum() == 4 + 30 + 2
    assert report.to_dict("records") == [{"marker": "CUB", "first_frame": 40, "last_frame": 44, "n_frames": 5}]
    summary = gap_summary(gappy, filled, ["CUB", "SIN"])
    assert list(summary.columns) == list(GAP_SUMMARY_COLUMNS)
    assert summary.to_dict("records") == [
        {
            "marker": "CUB",
            "n_frames": N,
            "n_filled_frames": 5,
            "n_missing_frames": 34,
            "longest_gap_frames": 30,
            "n_unfiltered_frames": 0,
        },
        {
            "marker": "SIN",
            "n_frames": N,
            "n_filled_frames": 0,
            "n_missing_frames": 2,
            "longest_gap_frames": 2,
            "n_unfiltered_frames": 0,
        },
    ]


def test_keep_with_no_filling_and_a_marker_missing_everywhere(trial):
    gappy = trial.copy()
    gappy[:, 1] = np.nan
    gappy[10:12, 0] = np.nan
    filled, report = fill_gaps(gappy, 0, ["CUB", "SIN"], SOURCE, unfillable="keep")
    np.testing.assert_array_equal(filled, gappy)
    assert len(report) == 0
    with pytest.raises(LoperInputError, match="unfillable must be 'error' or 'keep'"):
        fill_gaps(gappy, 0, ["CUB", "SIN"], SOURCE, unfillable="drop")


# ---------------------------------------------------------------- markers per frame for IK


def test_too_few_markers_names_frames_times_markers_and_file():
    X = np.ones((50, 4, 3)) * np.arange(4)[None, :, None]
    labels = ["LASI", "RASI", "LKNE", "LHEE"]
    X[10:13, [0, 1]] = np.nan  # two of four left
    X[30, 2] = np.nan  # three of four: enough
    X[40, [1, 3]] = np.nan
    require_markers_per_frame(X, labels, 2, source=SOURCE)  # two everywhere: no error
    t = 1.0 + np.arange(50) / 100.0
    with pytest.raises(LoperInputError) as err:
        require_markers_per_frame(X, labels, 3, time_s=t, source=SOURCE)
    assert str(err.value) == (
        f"{SOURCE}: 4 frame(s) hold fewer than 3 of the 4 weighted markers, too few to solve IK: "
        "frames 10..12 (t = 1.1000..1.1200 s), 40 (t = 1.4000 s); markers missing there: LASI, RASI, LHEE"
    )


def test_only_weighted_markers_count():
    X = np.zeros((5, 4, 3))
    X[2, :2] = np.nan
    labels = ["LASI", "RASI", "LKNE", "LHEE"]
    require_markers_per_frame(X, labels, 2, source=SOURCE)  # frame 2 holds LKNE and LHEE
    # ... but LHEE has weight 0: only LKNE counts there
    with pytest.raises(
        LoperInputError, match="1 frame.* fewer than 2 of the 3 weighted markers.*frames 2;.*: LASI, RASI$"
    ):
        require_markers_per_frame(X, labels, 2, weights={"LASI": 1, "LKNE": 1, "LHEE": 0, "RASI": 2}, source=SOURCE)
    with pytest.raises(LoperInputError, match="min_markers must be an integer >= 1, got 0"):
        require_markers_per_frame(X, labels, 0, source=SOURCE)


def test_summary_counts_frames_the_filter_left_unfiltered(trial):
    from loper_analysis.filtering import lowpass_finite_runs

    gappy = trial.copy()
    gappy[50:60, 1] = np.nan
    gappy[65:200, 1] = np.nan  # leaves frames 60..64 (5 frames) between two long gaps: too short to filter
    filtered, unfiltered = lowpass_finite_runs(gappy, FS, 10.0, 4)
    np.testing.assert_array_equal(filtered[60:65, 1], trial[60:65, 1])
    summary = gap_summary(gappy, filtered, ["CUB", "SIN"], unfiltered)
    assert summary[["n_missing_frames", "longest_gap_frames", "n_unfiltered_frames"]].values.tolist() == [
        [0, 0, 0],
        [145, 135, 5],
    ]


@pytest.mark.parametrize(
    "angles, up",
    [
        ((-90, 0, 0), [0.0, 0.0, 1.0]),  # Qualisys / Vicon, Z up: exactly, so that Z-up labs keep their numbers
        ((0, 0, 0), [0.0, 1.0, 0.0]),  # BTS, Y up, already OpenSim's frame
        ((90, 0, 0), [0.0, 0.0, -1.0]),
        ((0, 0, 90), [1.0, 0.0, 0.0]),
        ((-90, 30, 0), [0.0, 0.0, 1.0]),  # a heading turn about the model's vertical (Y) leaves up alone
        ((-90, 0, 30), [0.5, 0.0, np.sqrt(3) / 2]),  # a tilt about the model's Z moves it
        ((-80, 0, 0), [0.0, np.sin(np.radians(10)), np.cos(np.radians(10))]),
    ],
)
def test_lab_up_is_what_the_rotation_turns_into_the_models_plus_y(angles, up):
    from loper_analysis.motion.markers import MODEL_UP, lab_up

    got = lab_up(angles)
    np.testing.assert_allclose(got, up, rtol=0, atol=1e-15)
    np.testing.assert_allclose(rotate_markers(got, angles), MODEL_UP, rtol=0, atol=1e-15)
    if all(a % 90 == 0 for a in angles):
        assert got.tolist() == up  # quarter turns give exact axes


def test_lab_up_refuses_a_bad_rotation():
    from loper_analysis.motion.markers import lab_up

    with pytest.raises(LoperInputError, match="rotation_deg must be 3 finite angles"):
        lab_up((0.0, np.nan, 0.0))
