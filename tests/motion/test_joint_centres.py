"""Hip, knee and ankle centres of a static trial: the regression and the chord against their definitions, and the
knee alignment device and the widths against the centres a clinical lab's own Plug-in Gait stored in its file."""

from __future__ import annotations

from pathlib import Path

import ezc3d
import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.joint_centres import (
    DIRECTION_LEVER_M,
    KNEE_OFFSET_PER_THIGH,
    MARKER_DIAMETER_M,
    Landmarks,
    chord_centre,
    harrington_hip_centres,
    static_joint_centres,
    widths_from_processing,
)

DATA = Path(__file__).resolve().parents[1] / "data" / "c3d-parser"


def _rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r)) * np.linalg.det(q * np.sign(np.diag(r)))


def test_harrington_centres_lie_where_the_regression_puts_them_in_any_frame(rng):
    """A pelvis 0.25 m wide and 0.16 m deep, turned and moved anywhere: the centres are, in the spines' frame,
    x = -0.24 PD - 9.9 mm, y = -0.30 PW - 10.9 mm, z = +-(0.33 PW + 7.3 mm) (Harrington et al. 2007)."""
    width = 0.25
    lasi, rasi, back = np.array([0, 0, -width / 2]), np.array([0, 0, width / 2]), np.array([-0.16, 0.02, 0.0])
    depth = np.hypot(0.16, 0.02)
    R, t = _rotation(rng), rng.normal(size=3)
    hips = harrington_hip_centres(*(R @ p + t for p in (lasi, rasi, back)))
    # the frame: x forward in the plane of the spines, y up, z to the right
    x = np.array([0.16, -0.02, 0.0]) / depth
    y = np.cross([0, 0, 1.0], x)
    for side, sign in (("left", -1), ("right", 1)):
        local = np.array([-0.24 * depth - 0.0099, -0.30 * width - 0.0109, sign * (0.33 * width + 0.0073)])
        expected = R @ (local[0] * x + local[1] * y + local[2] * np.array([0, 0, 1.0])) + t
        np.testing.assert_allclose(hips[side][0], expected, atol=1e-12)


def test_chord_centre_is_at_the_offset_with_the_proximal_centre_at_a_right_angle(rng):
    """The centre lies at the offset from the lateral marker, sees the proximal centre at 90 degrees, lies in the
    plane of the three points and on the side away from the wand."""
    hip, knee_marker, wand = np.array([0.05, 0.42, 0.09]), np.array([0.0, 0.0, 0.06]), np.array([0.02, 0.2, 0.14])
    R, t = _rotation(rng), rng.normal(size=3)
    offset = 0.062
    c = chord_centre(R @ hip + t, R @ wand + t, R @ knee_marker + t, offset)[0]
    c = R.T @ (c - t)  # back in the construction's frame
    assert np.linalg.norm(c - knee_marker) == pytest.approx(offset, abs=1e-12)
    assert np.dot(hip - c, knee_marker - c) == pytest.approx(0.0, abs=1e-12)
    normal = np.cross(wand - knee_marker, hip - knee_marker)
    assert np.dot(c - knee_marker, normal) == pytest.approx(0.0, abs=1e-12)
    assert c[2] < knee_marker[2]  # medial: away from the lateral wand


def _static(lab: str):
    """A lab's static trial, averaged over its frames (1, n_markers, 3) in m, its labels and PROCESSING values."""
    c = ezc3d.c3d(str(DATA / lab / "static.c3d"))
    labels = [s.strip() for s in c["parameters"]["POINT"]["LABELS"]["value"]]
    P = c["data"]["points"][:3].astype(float)
    P[:, np.all(P == 0, axis=0)] = np.nan
    P = P[:, np.isfinite(P).any(axis=(0, 2))]  # points never present (modelled outputs Nexus left empty) out
    labels = [lab for lab, keep in zip(labels, np.isfinite(c["data"]["points"][0]).any(axis=1)) if keep]
    processing = {k: v["value"][0] for k, v in c["parameters"]["PROCESSING"].items() if k != "__METADATA__"}
    return labels, (np.nanmean(P, axis=2).T / 1000.0)[None], processing


def test_knee_device_and_widths_give_the_centres_the_labs_plug_in_gait_stored():
    """SYD's static trial holds a knee alignment device on each knee and Nexus's own knee and ankle centres
    (``LKJC``, ``LAJC``, ...): the device's origin moved along its axis by half the knee width plus the marker
    radius gives the knee centres within 3.5 mm (0.1 mm on the left; on the right Nexus's axis lies 3 degrees from
    the device's arm), the malleoli's midpoint the ankle centres within 2.1 mm. (Nexus's chord of the ankle turns
    by the tibial torsion it stores, which this file sets: the chord here, without it, is 6-8 mm away.)"""
    labels, X, processing = _static("SYD")
    widths = widths_from_processing(processing)
    assert widths["knee_left"] == pytest.approx(0.111) and widths["ankle_right"] == pytest.approx(0.062)
    assert "marker_diameter" not in widths  # not stored: Plug-in Gait's 14 mm
    centres = static_joint_centres(labels, X, Landmarks(knee_medial="", ankle_medial=""), widths, up=(0, 0, 1))
    got = dict(zip(centres.names, centres.markers_m[0]))
    for name, within_m in (("LKJC", 0.0005), ("RKJC", 0.0035)):
        assert np.linalg.norm(got[name] - X[0, labels.index(name)]) < within_m, name
    assert centres.methods["LKJC"].startswith("knee alignment device: LKNE along its axis by half the knee width")
    assert centres.methods["LAJC"].startswith("chord of the knee centre, shank wand and LANK, half the ankle width")
    mid = static_joint_centres(labels, X, Landmarks(knee_medial="", ankle_medial="MED"), widths, up=(0, 0, 1))
    got = dict(zip(mid.names, mid.markers_m[0]))
    for name in ("LAJC", "RAJC"):
        assert np.linalg.norm(got[name] - X[0, labels.index(name)]) < 0.0021, name
    assert mid.methods["LAJC"] == "midpoint of LANK and LMED"


def test_without_widths_the_offset_is_the_models_proportion_and_the_method_says_so():
    labels, X, _ = _static("SYD")
    centres = static_joint_centres(labels, X, Landmarks(knee_medial="", ankle_medial=""), {}, up=(0, 0, 1))
    got = dict(zip(centres.names, centres.markers_m[0]))
    hip, knee_marker = got["LHJC"], X[0, labels.index("LKNE")]
    expected = KNEE_OFFSET_PER_THIGH * np.linalg.norm(knee_marker - hip)
    assert np.linalg.norm(got["LKJC"] - knee_marker) == pytest.approx(expected, rel=1e-12)
    assert "no knee width stored" in centres.methods["LKJC"]
    assert MARKER_DIAMETER_M == 0.014


def test_direction_markers_point_forward_along_the_spines_and_up_from_the_ankles():
    labels, X, _ = _static("QCMAS")
    lm = Landmarks()
    centres = static_joint_centres(labels, X, lm, {}, up=(0, 0, 1))
    got = dict(zip(centres.names, centres.markers_m[0]))
    g = {n: X[0, labels.index(n)] for n in ("LASI", "RASI", "LPSI", "RPSI")}
    forward = 0.5 * (g["LASI"] + g["RASI"] - g["LPSI"] - g["RPSI"])
    hips = 0.5 * (got["LHJC"] + got["RHJC"])
    unit = forward / np.linalg.norm(forward)
    np.testing.assert_allclose(got["PELVIS_FRONT"], hips + DIRECTION_LEVER_M * unit)
    np.testing.assert_allclose(got["PELVIS_BACK"], hips - DIRECTION_LEVER_M * unit)
    np.testing.assert_allclose(got["LFOOT_UP"], got["LAJC"] + [0, 0, DIRECTION_LEVER_M])
    np.testing.assert_allclose(got["LFOOT_DOWN"], got["LAJC"] - [0, 0, DIRECTION_LEVER_M])
    assert centres.methods["LKJC"] == "midpoint of LKNE and LMKNE"


def test_a_missing_landmark_is_named():
    labels, X, _ = _static("QCMAS")
    keep = [i for i, n in enumerate(labels) if n not in ("RANK", "LPSI")]
    with pytest.raises(LoperInputError) as err:
        static_joint_centres([labels[i] for i in keep], X[:, keep], Landmarks(), {}, source="static.trc")
    message = str(err.value)
    assert message.startswith("static.trc: the joint centres of the static trial need the marker(s)")
    assert "LPSI and RPSI, or SACR" in message and "RANK" in message
