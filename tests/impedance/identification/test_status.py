"""loper_analysis.impedance.identification.joint_status: the rules of a fitted joint row, each on a known case."""

from __future__ import annotations

import numpy as np
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.impedance.identification import (
    AT_BOUND_FRACTION,
    COUPLING_CORRELATION,
    DEFAULT_PLAUSIBLE_RANGES,
    MIN_VAF_PCT,
    joint_status,
    strongest_coupling,
)

LOWER, UPPER = (0.0, 0.0), (200.0, 10.0)
NARROW = (1.0, 0.1)


def status(estimate, vaf=99.0, widths=NARROW, lower=LOWER, upper=UPPER, joint="knee", **kw):
    """The status of an interval of ``widths`` centred on ``estimate``, cut at the bounds."""
    est, half = np.asarray(estimate, float), np.asarray(widths, float) / 2
    low, high = np.clip(est - half, lower, upper), np.clip(est + half, lower, upper)
    return joint_status(joint, estimate, low, high, vaf, lower, upper, **kw)


def test_defaults():
    assert MIN_VAF_PCT == 0.0 and AT_BOUND_FRACTION == 1e-6


def test_an_estimate_inside_the_bounds_is_ok():
    assert status((2.5, 0.1)) == ("ok", "")


def test_the_upper_bound_within_the_tolerance_is_not_identifiable():
    # 1e-6 of the K range is 2e-4 N·m/rad
    s, reason = status((200.0 - 1.5e-4, 0.1))
    assert s == "not_identifiable"
    assert reason == (
        "K_knee = 200 N·m/rad at its upper bound 200 N·m/rad "
        "(impedance.stiffness_bounds_nm_per_rad): the data ask for more stiffness than the bounds allow"
    )
    assert status((200.0 - 2.5e-4, 0.1)) == ("ok", "")
    s, reason = status((3.0, 10.0))
    assert s == "not_identifiable" and reason.startswith(
        "D_knee = 10 N·m·s/rad at its upper bound 10 N·m·s/rad (impedance.damping_bounds_nms_per_rad)"
    )


def test_a_lower_bound_of_zero_is_a_valid_estimate():
    """K 2.5e-15 N·m/rad (a knee early in swing) with an interval 0 ... 1.33 below the study's 3.5 stays ok."""
    assert status((2.49492168e-15, 0.126), widths=(2.66, 0.1)) == ("ok", "")
    assert status((3.0, 0.0), widths=(1.0, 0.2)) == ("ok", "")


def test_a_positive_lower_bound_is_not_identifiable():
    s, reason = status((5.0, 0.1), lower=(5.0, 0.0))
    assert s == "not_identifiable" and "K_knee = 5 N·m/rad at its lower bound 5 N·m/rad" in reason


@pytest.mark.parametrize("vaf, expected", [(-118.0, "failed"), (-0.01, "failed"), (0.0, "ok"), (18.6, "ok")])
def test_the_vaf_floor(vaf, expected):
    s, reason = status((2.5, 0.1), vaf=vaf)
    assert s == expected
    if expected == "failed":
        assert reason == (
            f"VAF {vaf:.3g} % below impedance.min_vaf_pct = 0 %: the model does not describe the knee response"
        )


def test_an_undefined_vaf_fails():
    s, reason = status((2.5, 0.1), vaf=np.nan)
    assert s == "failed" and "VAF of the knee undefined" in reason


def test_findings_add_up_and_the_most_severe_wins():
    """The campaign's case: K on the bound, VAF -118 %, wide interval -> failed, all three named."""
    s, reason = joint_status(
        "knee", (200.0, 8.8), (50.0, 8.55), (200.0, 9.05), -118.0, LOWER, UPPER, max_ci_fraction=0.5
    )
    assert s == "failed"
    parts = reason.split("; ")
    assert [p.split(" ")[0] for p in parts] == ["VAF", "K_knee", "95"]
    assert parts[2] == "95 % CI width K 150 N·m/rad, D 0.5 N·m·s/rad exceeds 0.5 of the bounds"
    # by default (1: only an unbounded interval) the width is no finding of its own
    s, reason = joint_status("knee", (200.0, 8.8), (50.0, 8.55), (200.0, 9.05), -118.0, LOWER, UPPER)
    assert s == "failed" and [p.split(" ")[0] for p in reason.split("; ")] == ["VAF", "K_knee"]


def test_not_converged_keeps_its_reason():
    assert status((200.0, 8.8), vaf=-118.0, success=False, message="max iterations") == (
        "failed",
        "optimiser did not converge: max iterations",
    )


def test_bad_shapes_are_refused():
    with pytest.raises(LoperInputError, match="knee: estimate must hold K and D"):
        joint_status("knee", (1.0, 2.0, 3.0), (0.5, 0.05), (1.5, 0.15), 99.0, LOWER, UPPER)


def test_an_interval_holding_zero_and_the_study_range_is_not_identifiable():
    """Knee D 0.055, 95 % CI -0.22 ... 0.33 (cut to 0 ... 0.33) holds 0 and the study's 0.02-0.14: no information."""
    s, reason = joint_status("knee", (2.0, 0.055), (1.0, 0.0), (3.0, 0.33), 99.0, LOWER, UPPER)
    assert s == "not_identifiable"
    assert reason == (
        "D_knee = 0.055 N·m·s/rad, 95 % CI 0 … 0.33 N·m·s/rad: holds both 0 and the plausible range "
        "0.02–0.14 N·m·s/rad (impedance.plausible_ranges), the data cannot tell the damping from 0"
    )


def test_an_interval_clear_of_zero_is_ok():
    """Hip D 2.0 ... 4.0 around 3.0 and hip K 40 ... 60: both informative."""
    assert joint_status("hip", (50.0, 3.0), (40.0, 2.0), (60.0, 4.0), 99.0, LOWER, UPPER) == ("ok", "")


@pytest.mark.parametrize(
    "low, high, expected",
    [
        (0.0, 0.119, "ok"),  # holds 0, excludes the top of the study's range and is narrower than it: D < 0.12
        (0.0, 0.14, "not_identifiable"),  # reaches the top exactly
        (9e-6, 0.5, "not_identifiable"),  # within 1e-6 of the bound range (1e-5 N·m·s/rad) of 0
        (2e-5, 0.1, "ok"),  # clear of 0 and narrower than the range: the damping is told from none
        (2e-5, 0.5, "not_identifiable"),  # clear of 0, but wider than the whole range 0.02-0.14
    ],
)
def test_the_edges_of_the_information_rule(low, high, expected):
    assert joint_status("knee", (2.0, 0.05), (1.0, low), (3.0, high), 99.0, LOWER, UPPER)[0] == expected


def test_the_plausible_range_can_be_given():
    """Hip K 0 ... 70: holds 0 and the study's 34-66; a range of 34-110 it neither reaches the top of nor spans."""
    assert status((30.0, 3.0), widths=(80.0, 1.0), joint="hip")[0] == "not_identifiable"
    assert status((30.0, 3.0), widths=(80.0, 1.0), joint="hip", plausible_range=((34.0, 110.0), (1.9, 4.6))) == (
        "ok",
        "",
    )
    with pytest.raises(LoperInputError, match="plausible_ranges of the hip: K and D each need"):
        status((30.0, 3.0), joint="hip", plausible_range=((66.0, 34.0), (1.9, 4.6)))


def test_the_default_ranges_are_the_study_s():
    assert DEFAULT_PLAUSIBLE_RANGES == {
        "hip": ((34.0, 66.0), (1.9, 4.6)),
        "knee": ((0.0, 3.5), (0.02, 0.14)),
        "ankle": ((0.0, 20.0), (0.0, 0.75)),
    }


def test_an_interval_wider_than_the_plausible_range_is_not_identifiable():
    """Knee D 0.2, 95 % CI 0.03 ... 0.37: clear of 0, but 0.34 wide against the study's 0.02-0.14 (0.12)."""
    s, reason = joint_status("knee", (2.0, 0.2), (1.5, 0.03), (2.5, 0.37), 99.0, LOWER, UPPER)
    assert s == "not_identifiable"
    assert reason == (
        "D_knee = 0.2 N·m·s/rad, 95 % CI 0.03 … 0.37 N·m·s/rad: wider than the plausible range 0.02–0.14 N·m·s/rad "
        "(impedance.plausible_ranges), the data cannot place the damping within it"
    )
    # a little narrower than the range (0.115): informative; a little wider (0.125): not; wholly above the range:
    # says D is above it
    assert joint_status("knee", (2.0, 0.1), (1.5, 0.045), (2.5, 0.16), 99.0, LOWER, UPPER) == ("ok", "")
    assert joint_status("knee", (2.0, 0.1), (1.5, 0.035), (2.5, 0.16), 99.0, LOWER, UPPER)[0] == "not_identifiable"
    assert joint_status("knee", (2.0, 0.5), (1.5, 0.3), (2.5, 0.7), 99.0, LOWER, UPPER) == ("ok", "")


def test_a_too_wide_interval_names_the_joint_it_trades_off_against():
    """The pulse on the thigh moves hip and knee alike: a knee D correlated -0.93 with the hip's D is named so."""
    args = ("knee", (2.0, 0.2), (1.5, 0.03), (2.5, 0.37), 99.0, LOWER, UPPER)
    s, reason = joint_status(*args, coupling=(("K_hip", -0.95), ("D_hip", -0.93)))
    assert s == "not_identifiable"
    assert reason.endswith(
        "the data cannot place the damping within it; it trades off against D_hip (correlation -0.93): "
        "the data cannot separate D_knee from D_hip"
    )
    assert "K_hip" not in reason  # K's interval (1 N·m/rad of 3.5) is informative: nothing to say about it
    weak = -(COUPLING_CORRELATION - 0.01)
    assert "trades off" not in joint_status(*args, coupling=(None, ("D_hip", weak)))[1]
    with pytest.raises(LoperInputError, match="knee: coupling must hold K and D"):
        joint_status(*args, coupling=(("D_hip", -0.9),))


def test_strongest_coupling_is_the_largest_correlation_with_another_joint():
    c = np.eye(6)
    c[2, 3] = c[3, 2] = 0.99  # K_knee with D_knee: the same joint, never named
    c[2, 0] = c[0, 2] = -0.92  # K_knee with K_hip
    c[2, 4] = c[4, 2] = 0.5
    c[3, 1] = c[1, 3] = -0.6  # D_knee with D_hip
    c[3, 5] = c[5, 3] = 0.7  # D_knee with D_ankle: the stronger
    assert strongest_coupling(c, "knee") == (("K_hip", -0.92), ("D_ankle", 0.7))
    assert strongest_coupling(c, "hip") == (("K_knee", -0.92), ("D_knee", -0.6))
    c[3, [0, 1, 4, 5]] = np.nan  # no finite standard error elsewhere: nothing to name
    assert strongest_coupling(c, "knee")[1] is None
    with pytest.raises(LoperInputError, match="correlation must be 6 x 6"):
        strongest_coupling(np.eye(4), "knee")
