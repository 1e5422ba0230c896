"""The plan scaled to the pilot fit's intervals widened to its perturbed pairs' scatter
(loper_analysis.planning.pilot_plan.widened_interval_scale, StrideCovariance.scaled), worked by hand."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from loper_analysis.constants import JOINTS
from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification.jackknife import WIDENED
from loper_analysis.planning.covariance import StrideCovariance
from loper_analysis.planning.pilot_plan import widened_interval_scale

#: Per-stride variances of K and D per joint (N²·m²/rad², N²·m²·s²/rad²) and a shared 1/N² part.
VARIANCE = np.array([400.0, 4.0, 25.0, 0.04, 1.0, 0.0004])


def _cov() -> StrideCovariance:
    c = np.diag(VARIANCE).copy()
    c[0, 2] = c[2, 0] = -0.9 * np.sqrt(VARIANCE[0] * VARIANCE[2])  # hip K and knee K traded off
    return StrideCovariance(c, np.zeros(6), None, 40, spread_covariance=np.diag(0.5 * VARIANCE))


def _rows(reasons: dict[str, str], se: dict[str, float], n_strides: int = 25) -> pd.DataFrame:
    return pd.DataFrame(
        [
            {
                "subject": "P01",
                "onset_ms": 175,
                "joint": joint,
                "n_strides": n_strides,
                "K_se_nm_per_rad": se.get(f"K_{joint}", 0.1),
                "D_se_nms_per_rad": se.get(f"D_{joint}", 0.001),
                "reason": reasons.get(joint, ""),
            }
            for joint in JOINTS
        ]
    )


def test_scaling_multiplies_the_sd_and_keeps_the_correlations():
    cov = _cov()
    scale = np.array([2.0, 1.0, 3.0, 1.0, 1.0, 1.0])
    scaled = cov.scaled(scale, "why")
    for n in (1, 20):
        np.testing.assert_allclose(scaled.sd_of(n), scale * cov.sd_of(n), rtol=1e-14)
    r = scaled.covariance[0, 2] / np.sqrt(scaled.covariance[0, 0] * scaled.covariance[2, 2])
    assert r == pytest.approx(-0.9, rel=1e-14) and scaled.note == "why"
    with pytest.raises(LoperInputError, match="scale must be 6 finite values > 0"):
        cov.scaled(np.zeros(6), "")


def test_a_widened_pilot_interval_sets_its_parameter_s_scale():
    """The pilot's ankle K widened, its reported SE twice the plan at its own 25 strides: scale 2 there, 1
    elsewhere; a widened SE below the plan's keeps 1 (the plan is never narrowed)."""
    cov = _cov()
    at_pilot = cov.sd_of(25)
    rows = _rows(
        {"ankle": f"K_ankle: {WIDENED} (jackknife SD ...)", "hip": f"D_hip: {WIDENED} (jackknife SD ...)"},
        {"K_ankle": 2.0 * at_pilot[4], "D_hip": 0.5 * at_pilot[1]},
    )
    scale, note = widened_interval_scale(rows, "P01", 175, cov)
    np.testing.assert_allclose(scale, [1.0, 1.0, 1.0, 1.0, 2.0, 1.0], rtol=1e-12)
    assert "K_ankle x2" in note and "D_hip x1" in note
    scaled = cov.scaled(scale, note)
    assert scaled.sd_of(25)[4] == pytest.approx(2.0 * at_pilot[4], rel=1e-12)


def test_no_widened_row_no_scale():
    cov = _cov()
    for rows in (_rows({}, {}), _rows({}, {}).drop(columns="reason"), None):
        scale, note = widened_interval_scale(rows, "P01", 175, cov)
        np.testing.assert_array_equal(scale, np.ones(6))
        assert note == ""
    # another onset's or subject's widening does not count
    rows = _rows({"ankle": f"K_ankle: {WIDENED}"}, {"K_ankle": 10.0})
    assert widened_interval_scale(rows, "P01", 50, cov)[1] == ""
    assert widened_interval_scale(rows, "P02", 175, cov)[1] == ""
