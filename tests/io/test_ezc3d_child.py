"""io/ezc3d_child.py: a payload written by hand becomes, in the child process, a C3D file whose every value ezc3d
reads back."""

from __future__ import annotations

import subprocess
import sys

import ezc3d
import numpy as np


def _payload(n_frames: int = 4, ratio: int = 2) -> dict[str, np.ndarray]:
    points = np.ones((4, 2, n_frames))
    points[:3] = np.arange(3 * 2 * n_frames, dtype=float).reshape(3, 2, n_frames) * 10.0  # mm
    analogs = np.linspace(-1.0, 1.0, 2 * n_frames * ratio).reshape(1, 2, n_frames * ratio)
    return {
        "point_rate_hz": np.float64(100.0),
        "point_unit": np.str_("mm"),
        "marker_labels": np.array(["A", "B"]),
        "points": points,
        "residuals": np.zeros((1, 2, n_frames)),
        "analog_rate_hz": np.float64(100.0 * ratio),
        "analog_labels": np.array(["Fz", "sync"]),
        "analog_units": np.array(["N", "V"]),
        "analogs": analogs,
    }


def _run_child(tmp_path, payload: dict) -> ezc3d.c3d:
    np.savez(tmp_path / "p.npz", **payload)
    out = tmp_path / "out.c3d"
    subprocess.run(
        [sys.executable, "-m", "loper_analysis.io.ezc3d_child", str(tmp_path / "p.npz"), str(out)],
        check=True,
        capture_output=True,
    )
    return ezc3d.c3d(str(out))


def test_a_plain_payload_is_written_as_given(tmp_path):
    payload = _payload()
    c = _run_child(tmp_path, payload)
    assert list(c["parameters"]["POINT"]["LABELS"]["value"]) == ["A", "B"]
    assert list(c["parameters"]["ANALOG"]["UNITS"]["value"]) == ["N", "V"]
    assert float(c["parameters"]["ANALOG"]["RATE"]["value"][0]) == 200.0
    np.testing.assert_array_equal(c["data"]["points"][:3], payload["points"][:3])
    np.testing.assert_allclose(c["data"]["analogs"], payload["analogs"], rtol=1e-7)


def test_extras_set_first_frame_offsets_plates_and_events(tmp_path):
    payload = _payload()
    payload["analogs"] = np.array([[[0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0], [1.0] * 8]])
    corners = np.array([[0.0, 600.0, 600.0, 0.0], [0.0, 0.0, 400.0, 400.0], [0.0, 0.0, 0.0, 0.0]])  # (3, 4) mm
    payload.update(
        {
            "first_frame": np.int64(25),
            "analog_scales": np.array([2.0, 0.5]),
            "analog_offsets": np.array([100, 0], dtype=np.int64),
            "fp_type": np.array([2], dtype=np.int64),
            "fp_corners": corners[:, :, None],
            "fp_origin": np.array([[1.0], [2.0], [-40.0]]),
            "fp_channel": np.array([[1], [2], [1], [2], [1], [2]], dtype=np.int64),
            "fp_cal": np.eye(6)[:, :, None],
            "event_contexts": np.array(["Left"]),
            "event_labels": np.array(["Foot Strike"]),
            "event_times": np.array([[1.0], [2.5]]),
        }
    )
    c = _run_child(tmp_path, payload)
    assert c["header"]["points"]["first_frame"] == 25
    A = c["parameters"]["ANALOG"]
    np.testing.assert_array_equal(A["SCALE"]["value"], [2.0, 0.5])
    np.testing.assert_array_equal(A["OFFSET"]["value"], [100, 0])
    # the file stores value / scale + offset; ezc3d applies (stored - offset) * scale
    np.testing.assert_allclose(c["data"]["analogs"], payload["analogs"], rtol=1e-6)
    FP = c["parameters"]["FORCE_PLATFORM"]
    assert int(FP["USED"]["value"][0]) == 1 and int(FP["TYPE"]["value"][0]) == 2
    np.testing.assert_array_equal(np.asarray(FP["CORNERS"]["value"])[:, :, 0], corners)
    np.testing.assert_array_equal(np.asarray(FP["ORIGIN"]["value"]).ravel(), [1.0, 2.0, -40.0])
    np.testing.assert_array_equal(np.asarray(FP["CHANNEL"]["value"]).ravel(), [1, 2, 1, 2, 1, 2])
    E = c["parameters"]["EVENT"]
    assert list(E["CONTEXTS"]["value"]) == ["Left"] and list(E["LABELS"]["value"]) == ["Foot Strike"]
    np.testing.assert_allclose(np.asarray(E["TIMES"]["value"]).ravel(), [1.0, 2.5])
