"""Human-range checks of marker data (loper_analysis.motion.plausibility) against known answers."""

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.motion.ik import marker_positions
from loper_analysis.motion.model import MARKERS, SCALE_MEASUREMENTS, build_lower_body_model
from loper_analysis.motion.plausibility import (
    marker_extent_m,
    measurement_scale_factors,
    require_ik_fit,
    require_marker_extent,
    require_scale_factors,
)


def test_marker_extent_is_the_median_largest_distance():
    X = np.zeros((3, 3, 3))
    X[:, 1, 0] = [1.0, 1.5, 2.0]  # 1, 1.5, 2 m from the first marker
    X[:, 2, 1] = 0.5
    X[1, 1] = np.nan  # frame 1: only 0.5 m left
    assert marker_extent_m(X) == pytest.approx(np.median([np.hypot(1.0, 0.5), 0.5, np.hypot(2.0, 0.5)]))
    assert require_marker_extent(X, "a.c3d") == pytest.approx(np.hypot(1.0, 0.5))
    with pytest.raises(LoperInputError, match=r"a\.c3d: marker extent .* is 1118 m, outside .* 0\.1 \.\. 5 m"):
        require_marker_extent(1000 * X, "a.c3d")
    with pytest.raises(LoperInputError, match=r"is 0\.001118 m"):
        require_marker_extent(X / 1000, "a.c3d")


def test_scale_factors_of_markers_spread_by_a_known_factor():
    model = build_lower_body_model(1.75, 70.0)
    X = 1.1 * marker_positions(model, {})  # every distance 1.1 times the model's
    factors = measurement_scale_factors(model, SCALE_MEASUREMENTS, np.repeat(X, 3, axis=0), list(MARKERS))
    np.testing.assert_allclose(list(factors.values()), 1.1, rtol=1e-9)
    require_scale_factors(factors, "static.trc")
    with pytest.raises(LoperInputError, match=r"static\.trc: scale factor\(s\) outside 0\.5 \.\. 2 .*pelvis 2\.2"):
        require_scale_factors({k: 2 * v for k, v in factors.items()}, "static.trc")


def test_ik_fit_limit_counts_frames_over_the_rms_limit():
    rms = np.r_[np.full(8, 0.005), 0.03, 0.05, np.nan]
    require_ik_fit(rms, "walk.trc", max_rms_m=0.02, max_fraction=0.2)  # 2 of 10 frames: 20 % allowed
    with pytest.raises(
        LoperInputError,
        match=r"walk\.trc: IK marker RMS error exceeds 20 mm in 2 of 10 frames "
        r"\(20\.0 % > 10 %\); mean RMS 12 mm, largest 50 mm",
    ):
        require_ik_fit(rms, "walk.trc", max_rms_m=0.02)


def test_ik_fit_warns_at_20_mm_and_stops_at_60_mm_by_default():
    # OpenSim's gait2392 tutorial solves at about 22 mm mean RMS: poor, but the data are right
    tutorial = np.r_[np.full(90, 0.022), np.full(10, 0.035)]
    warning = require_ik_fit(tutorial, "walk1.trc")
    assert warning.startswith(
        "walk1.trc: IK marker RMS error exceeds 20 mm in 100 of 100 frames (100.0 %); mean RMS 23.3 mm, largest 35 mm"
    )
    assert "ik.warn_marker_rms_m" in warning
    assert require_ik_fit(np.full(100, 0.012), "walk1.trc") is None
    assert require_ik_fit(tutorial, "walk1.trc", warn_rms_m=None) is None
    # a unit or label mistake: 97 mm in every frame (a trial walked the other way, before it was turned)
    with pytest.raises(
        LoperInputError,
        match=r"walk\.trc: IK marker RMS error exceeds 60 mm in 100 of 100 frames "
        r"\(100\.0 % > 10 %\); mean RMS 97 mm, largest 97 mm: wrong marker "
        r"unit, labels or model\? \(limit: ik\.max_marker_rms_m\)",
    ):
        require_ik_fit(np.full(100, 0.097), "walk.trc")
    # 10 % of the frames over 60 mm is still allowed (e.g. a marker swapped for a moment), 11 % is not
    require_ik_fit(np.r_[np.full(90, 0.01), np.full(10, 0.08)], "walk.trc")
    with pytest.raises(LoperInputError, match="exceeds 60 mm in 11 of 100 frames"):
        require_ik_fit(np.r_[np.full(89, 0.01), np.full(11, 0.08)], "walk.trc")
