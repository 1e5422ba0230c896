"""A trial's markers prepared for OpenSim (motion.trial_markers): renamed, cropped, filled and turned
against hand-built lab trajectories, the per-marker summary against the gaps put in, bad input by its message."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d import C3DRecording
from loper_analysis.motion.markers import GAP_SUMMARY_COLUMNS
from loper_analysis.motion.trial_markers import TRIAL_MARKER_COLUMNS, MarkerSettings, prepared_markers

RATE = 100.0
LABELS = ["Sub:L1", "Sub:L2", "Sub:L3", "Sub:L4"]
LABEL_MAP = {"L1": "RASI", "L2": "LASI", "L3": "RPSI", "L4": "LPSI"}
FIXED = MarkerSettings(walking_direction="fixed", cutoff_hz=None)


def _lab_markers(n: int = 50) -> np.ndarray:
    """Four markers (n, 4, 3) in a Z-up lab, each on a quadratic path in time (m)."""
    t = np.arange(n) / RATE
    base = np.array([[0.1, 0.1, 1.0], [0.1, -0.1, 1.0], [-0.1, 0.08, 1.05], [-0.1, -0.08, 1.05]])
    drift = np.stack([0.02 * t + 0.1 * t**2, 0.01 * t, -0.03 * t**2], axis=-1)
    return base[None] + drift[:, None]


def _recording(markers: np.ndarray, first_frame: int = 0) -> C3DRecording:
    return C3DRecording("walk.c3d", list(LABELS), markers, RATE, first_frame=first_frame)


def test_markers_are_renamed_filled_and_turned_into_the_model_frame():
    """(-90, 0, 0) takes lab (x, y, z) to model (x, z, -y); a 3-frame gap on a quadratic path is filled exactly."""
    lab = _lab_markers()
    raw = lab.copy()
    raw[20:23, 1] = np.nan
    out = prepared_markers(_recording(raw), LABEL_MAP, FIXED, "S01 walk")
    assert out.names == ["RASI", "LASI", "RPSI", "LPSI"]
    np.testing.assert_allclose(out.time_s, np.arange(50) / RATE, rtol=0, atol=1e-15)
    expected = np.stack([lab[..., 0], lab[..., 2], -lab[..., 1]], axis=-1)
    np.testing.assert_allclose(out.markers_m, expected, rtol=0, atol=1e-12)
    assert out.gaps.to_dict("records") == [{"marker": "LASI", "first_frame": 20, "last_frame": 22, "n_frames": 3}]
    summary = out.summary
    assert list(summary.columns) == ["label", *GAP_SUMMARY_COLUMNS, *TRIAL_MARKER_COLUMNS[1:]]
    assert list(summary["label"]) == LABELS
    assert list(summary["n_filled_frames"]) == [0, 3, 0, 0]
    assert list(summary["n_missing_frames"]) == [0, 0, 0, 0]
    assert set(summary["n_frames_too_few_markers"]) == {0}
    assert (summary["first_time_s"].iloc[0], summary["last_time_s"].iloc[0]) == (0.0, 0.49)
    assert list(summary.loc[0, ["turn_deg", "rotation_x_deg", "rotation_y_deg", "rotation_z_deg"]]) == [
        0.0,
        -90.0,
        0.0,
        0.0,
    ]


def test_a_long_gap_is_kept_missing_and_counted():
    """A gap longer than max_gap_frames stays NaN; with two markers left in those frames IK lacks markers."""
    raw = _lab_markers()
    raw[10:16, 0] = np.nan  # 6 frames > 3
    raw[10:16, 1] = np.nan
    settings = MarkerSettings(walking_direction="fixed", cutoff_hz=None, max_gap_frames=3)
    out = prepared_markers(_recording(raw), LABEL_MAP, settings, "S01 walk")
    assert np.isnan(out.markers_m[10:16, :2]).all() and np.isfinite(out.markers_m[:, 2:]).all()
    assert len(out.gaps) == 0
    assert list(out.summary["n_missing_frames"]) == [6, 6, 0, 0]
    assert set(out.summary["n_frames_too_few_markers"]) == {6}


def test_span_and_duration_crop_on_the_file_clock():
    """The span 0.25 .. 0.35 s on a file starting at frame 10 keeps frames 15 .. 25; the first 0.2 s keep 20."""
    rec = _recording(_lab_markers(), first_frame=10)
    span = prepared_markers(
        rec, LABEL_MAP, MarkerSettings(walking_direction="fixed", cutoff_hz=None, span_s=(0.25, 0.35)), "S01"
    )
    np.testing.assert_allclose(span.time_s, np.arange(25, 36) / RATE, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        span.markers_m[0, 0], [0.1 + 0.02 * 0.15 + 0.1 * 0.15**2, 1.0 - 0.03 * 0.15**2, -0.1 - 0.01 * 0.15], atol=1e-12
    )
    assert (span.summary["first_time_s"].iloc[0], span.summary["last_time_s"].iloc[0]) == (0.25, 0.35)
    head = prepared_markers(
        rec, LABEL_MAP, MarkerSettings(walking_direction="fixed", cutoff_hz=None, duration_s=0.2), "S01"
    )
    np.testing.assert_allclose(head.time_s, np.arange(10, 30) / RATE, rtol=0, atol=1e-12)


def test_bad_trials_are_refused_by_name():
    """An empty span, a missing required marker and a file without markers name the file and what to fix."""
    rec = _recording(_lab_markers())
    with pytest.raises(
        LoperInputError,
        match=r"^S01 walk: the trial's span 2 \.\. 3 s \(markers.trial_spans_s\) holds no frame of the file "
        r"\(0.0000 \.\. 0.4900 s\)",
    ):
        prepared_markers(rec, LABEL_MAP, MarkerSettings(walking_direction="fixed", span_s=(2.0, 3.0)), "S01 walk")
    with pytest.raises(
        LoperInputError, match=r"^S01 walk: model marker\(s\) .*RHEE.* not provided by any label of the file"
    ):
        prepared_markers(
            rec, LABEL_MAP, MarkerSettings(walking_direction="fixed", required_markers=("RASI", "RHEE")), "S01 walk"
        )
    empty = C3DRecording(
        "forces.c3d",
        [],
        np.zeros((5, 0, 3)),
        RATE,
        analog_labels=["Fx1", "Fy1"],
        analog_units=["N", "N"],
        analogs=np.zeros((5, 2)),
    )
    with pytest.raises(
        LoperInputError,
        match=r"^S01 walk: no markers \(POINT:LABELS holds no marker trajectory\): "
        r"the file holds 2 analog channel\(s\) \(Fx1, Fy1\)",
    ):
        prepared_markers(empty, None, FIXED, "S01 walk")


def test_static_settings_neither_fill_nor_filter():
    """for_static keeps every other setting and sets max_gap_frames 0 and no cutoff."""
    walking = MarkerSettings(walking_direction="fixed", max_gap_frames=7, cutoff_hz=8.0, duration_s=1.5)
    static = walking.for_static()
    assert (static.max_gap_frames, static.cutoff_hz, static.duration_s, static.walking_direction) == (
        0,
        None,
        1.5,
        "fixed",
    )
