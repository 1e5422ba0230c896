"""loper_analysis.identification.joint_status: the rules of a fitted joint row, each on a known case."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.identification import AT_BOUND_FRACTION, MIN_VAF_PCT, joint_status

LOWER, UPPER = (0.0, 0.0), (200.0, 10.0)
NARROW = (1.0, 0.1)


def status(estimate, vaf=99.0, widths=NARROW, lower=LOWER, upper=UPPER, **kw):
    return joint_status("knee", estimate, widths, vaf, lower, upper, **kw)


def test_defaults():
    assert MIN_VAF_PCT == 0.0 and AT_BOUND_FRACTION == 1e-6


def test_an_estimate_inside_the_bounds_is_ok():
    assert status((2.5, 0.1)) == ("ok", "")


def test_the_upper_bound_within_the_tolerance_is_not_identifiable():
    # 1e-6 of the K range is 2e-4 N·m/rad
    s, reason = status((200.0 - 1.5e-4, 0.1))
    assert s == "not_identifiable"
    assert reason == ("K_knee = 200 N·m/rad at its upper bound 200 N·m/rad "
                      "(identification.stiffness_bounds_nm_per_rad): the data ask for more stiffness than the bounds allow")
    assert status((200.0 - 2.5e-4, 0.1)) == ("ok", "")
    s, reason = status((3.0, 10.0))
    assert s == "not_identifiable" and reason.startswith("D_knee = 10 N·m·s/rad at its upper bound 10 N·m·s/rad "
                                                         "(identification.damping_bounds_nms_per_rad)")


def test_a_lower_bound_of_zero_is_a_valid_estimate():
    """The default study's S03 knee at 175 ms: K 2.5e-15 N·m/rad stays ok with an empty reason."""
    assert status((2.49492168e-15, 0.126), widths=(2.66, 0.26)) == ("ok", "")
    assert status((3.0, 0.0)) == ("ok", "")


def test_a_positive_lower_bound_is_not_identifiable():
    s, reason = status((5.0, 0.1), lower=(5.0, 0.0))
    assert s == "not_identifiable" and "K_knee = 5 N·m/rad at its lower bound 5 N·m/rad" in reason


@pytest.mark.parametrize("vaf, expected", [(-118.0, "failed"), (-0.01, "failed"), (0.0, "ok"), (18.6, "ok")])
def test_the_vaf_floor(vaf, expected):
    s, reason = status((2.5, 0.1), vaf=vaf)
    assert s == expected
    if expected == "failed":
        assert reason == (f"VAF {vaf:.3g} % below identification.min_vaf_pct = 0 %: "
                          "the model does not describe the knee response")


def test_an_undefined_vaf_fails():
    s, reason = status((2.5, 0.1), vaf=np.nan)
    assert s == "failed" and "VAF of the knee undefined" in reason


def test_findings_add_up_and_the_most_severe_wins():
    """The campaign's case: K on the bound, VAF -118 %, wide interval -> failed, all three named."""
    s, reason = status((200.0, 8.8), vaf=-118.0, widths=(150.0, 0.5))
    assert s == "failed"
    parts = reason.split("; ")
    assert [p.split(" ")[0] for p in parts] == ["VAF", "K_knee", "95"]
    assert parts[2] == "95 % CI width K 150 N·m/rad, D 0.5 N·m·s/rad exceeds 0.5 of the bounds"


def test_not_converged_keeps_its_reason():
    assert status((200.0, 8.8), vaf=-118.0, success=False, message="max iterations") == (
        "failed", "optimiser did not converge: max iterations")


def test_bad_shapes_are_refused():
    with pytest.raises(LoperInputError, match="knee: estimate must hold K and D"):
        joint_status("knee", (1.0, 2.0, 3.0), NARROW, 99.0, LOWER, UPPER)
