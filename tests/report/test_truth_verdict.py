"""The rule of the truth verdicts (loper_analysis.report.truth_verdict) and their lines on the front page
(loper_analysis.report.truth_page), on small constructed tables: a correct chain's counts are green, a broken
chain's red, a calibration of another design gives way to the run's own counts with the fallback's wording.

The binomial probabilities are computed here from their definitions (sums of ``comb(n, k) p^k (1 - p)^(n - k)``).
"""

from __future__ import annotations

import math

import pandas as pd
import pytest

from loper_analysis.errors import LoperInputError
from loper_analysis.report.calibration import Calibration, CalibrationRow
from loper_analysis.report.truth_page import truth_verdicts_html
from loper_analysis.report.truth_verdict import share_check, truth_verdicts

FINGERPRINT = "0123456789abcdef"
OTHER = "fedcba9876543210"


def _pmf(k: int, n: int, p: float) -> float:
    return math.comb(n, k) * p**k * (1 - p) ** (n - k)


def _cdf(k: int, n: int, p: float) -> float:
    return sum(_pmf(i, n, p) for i in range(k + 1))


def _two_sided(k: int, n: int, p: float) -> float:
    """The two-sided binomial p-value: the probability of every count no more likely than ``k``."""
    own = _pmf(k, n, p)
    return min(1.0, sum(_pmf(i, n, p) for i in range(n + 1) if _pmf(i, n, p) <= own * (1 + 1e-7)))


def _calibration(in_ci: int, within: tuple[int, int], n: int = 100, fingerprint: str = FINGERPRINT) -> Calibration:
    """A calibration run of 34 subjects: per joint and parameter ``n`` fits, ``in_ci`` intervals holding the truth,
    ``within`` (K, D) estimates within tolerance."""
    rows = tuple(
        CalibrationRow(joint, p, n, in_ci, within[k], 10)
        for joint in ("hip", "knee", "ankle")
        for k, p in enumerate("KD")
    )
    return Calibration(
        date="2026-12-01",
        seed=2024,
        n_subjects=34,
        n_subject_onset_fits=102,
        mode="coordinates",
        code_version="loper-analysis 0.1.0, commit abc1234",
        design_fingerprint=fingerprint,
        tolerance={"K": (0.10, 2.0), "D": (0.15, 0.05)},
        rows=rows,
    )


def _truth(n_fits, k_in, d_in, k_within, d_within, n_failed=(0, 0, 1)) -> pd.DataFrame:
    """A run's truth recovery of 3 subjects: per joint (hip, knee, ankle) its fits and counts."""
    return pd.DataFrame(
        {
            "joint": ["hip", "knee", "ankle"],
            "n_subjects": 3,
            "n_fits": n_fits,
            "n_failed": n_failed,
            "K_n_truth_in_ci95": k_in,
            "D_n_truth_in_ci95": d_in,
            "K_n_within_tolerance": k_within,
            "D_n_within_tolerance": d_within,
        }
    )


#: A correct chain: 26 fits, 50 of 52 intervals hold the truth, K 25 and D 24 within tolerance.
CORRECT = _truth([9, 9, 8], [9, 9, 7], [9, 8, 8], [9, 8, 8], [8, 9, 7])


def test_a_correct_chain_s_counts_are_green():
    calibration = _calibration(95, (93, 93))  # 570 / 600 intervals, K and D 279 / 300 within tolerance
    v = truth_verdicts(CORRECT, calibration, FINGERPRINT)
    assert v.basis == "calibration"
    c = v.intervals
    assert (c.n, c.total, c.calibration) == (50, 52, (570, 600))
    low, high = c.calibration_interval  # Clopper-Pearson: 2.5 % of the binomial beyond each end
    assert 1 - _cdf(569, 600, low) == pytest.approx(0.025, rel=1e-6)
    assert _cdf(570, 600, high) == pytest.approx(0.025, rel=1e-6)
    assert c.target_met and c.p_consistent == pytest.approx(_two_sided(50, 52, 0.95), rel=1e-9)
    assert c.verdict is True
    k, d = v.within["K"], v.within["D"]
    assert (k.n, k.total, k.calibration, d.n, d.calibration) == (25, 26, (279, 300), 24, (279, 300))
    assert k.p_consistent == pytest.approx(_two_sided(25, 26, 0.93), rel=1e-9)
    assert d.p_consistent == pytest.approx(_two_sided(24, 26, 0.93), rel=1e-9)
    assert k.verdict is d.verdict is v.estimates is True
    page = truth_verdicts_html(v, CORRECT)
    assert (
        "<b>Recovering the truth</b> (3 synthetic subjects, 26 joint fits, 1 failed): verdict from the calibration run "
        "of 2026-12-01, "
        '<span data-q="verdict|calibration|n_subject_onset_fits" data-v="102">102</span> fits '
        '(<span data-q="verdict|calibration|n_subjects" data-v="34">34</span> subjects, seed 2024), design '
        "fingerprint matches this run." in page
    )
    assert page.count('class="lf-mark lf-ok">✓') == 2 and "lf-bad" not in page
    assert "<b>Intervals hold the truth</b>: calibration " in page
    assert "/600 (95 %; 93–97 %), target 90–98 %; this run " in page and "/52 (96 %), agreeing (p = " in page
    assert "<b>Estimates within tolerance</b>: calibration K " in page and "target ≥ 90 %; this run K " in page


def test_a_broken_chain_is_red():
    """Intervals that all miss the truth, estimates of the wrong sign (none within tolerance)."""
    broken = _truth([9, 9, 8], [0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0])
    v = truth_verdicts(broken, _calibration(95, (93, 93)), FINGERPRINT)
    assert v.intervals.target_met and v.intervals.p_consistent == pytest.approx(_two_sided(0, 52, 0.95), rel=1e-6)
    assert v.intervals.p_consistent < 1e-60 and v.intervals.verdict is False
    assert v.within["K"].p_consistent == pytest.approx(0.07**26, rel=1e-6)  # the only count as unlikely as 0
    assert v.estimates is False
    page = truth_verdicts_html(v, broken)
    assert "<b>Intervals miss the truth in this run</b>" in page and "disagreeing (p &lt; 0.0001)" in page
    assert "<b>Estimates off the truth in this run</b>" in page and page.count("lf-bad") == 2


def test_a_correct_chain_at_a_design_that_misses_the_target_is_green_and_says_so():
    """The calibration puts 60 % of K and 50 % of D within tolerance: the design misses the 90 % target; this run's
    16 / 26 and 12 / 26 agree with it (the default study's counts): the chain is the calibrated one (green), and
    the line says that this design's precision misses the target."""
    run = _truth([9, 9, 8], [8, 8, 7], [9, 7, 6], [6, 5, 5], [4, 4, 4])
    v = truth_verdicts(run, _calibration(93, (60, 50)), FINGERPRINT)
    k, d = v.within["K"], v.within["D"]
    assert (k.n, d.n) == (16, 12) and not k.target_met and not d.target_met
    assert k.p_consistent == pytest.approx(_two_sided(16, 26, 0.6), rel=1e-9) and k.p_consistent > 0.5
    assert d.p_consistent == pytest.approx(_two_sided(12, 26, 0.5), rel=1e-9) and d.p_consistent > 0.5
    assert v.estimates is True
    page = truth_verdicts_html(v, run)
    assert "<b>Estimates as a correct chain places them</b>: calibration K " in page and "agreeing (p = " in page
    assert "(this design's precision misses it)" in page


def test_a_calibration_whose_intervals_always_hold_the_truth_misses_the_target():
    """600 / 600: the Clopper-Pearson interval starts at 0.025^(1/600) = 0.9939, above the target's 98 %: the
    intervals are too wide to inform."""
    v = truth_verdicts(
        _truth([9, 9, 8], [9, 9, 8], [9, 9, 8], [9, 9, 8], [9, 9, 8]), _calibration(100, (95, 95)), FINGERPRINT
    )
    assert v.intervals.calibration_interval[0] == pytest.approx(0.025 ** (1 / 600), rel=1e-9)
    assert v.intervals.p_consistent == 1.0 and not v.intervals.target_met and v.intervals.verdict is False
    assert "<b>Intervals miss the target at this design</b>" in truth_verdicts_html(v, CORRECT)


def test_a_calibration_of_another_design_gives_way_to_this_run_s_own_counts():
    """45 / 52 intervals are not rejected by the 90 % end (P(X <= 45 | 52, 0.9) = 0.26): too few to decide (grey);
    K 16 / 26 and D 12 / 26 within tolerance fall short of 90 % (P(X <= 16 | 26, 0.9) = 1.2e-4), but without a
    calibration of this design a correct chain's share is not known: grey, the probability stated."""
    run = _truth([9, 9, 8], [8, 8, 7], [8, 8, 6], [6, 5, 5], [4, 4, 4])
    v = truth_verdicts(run, _calibration(95, (93, 93), fingerprint=OTHER), FINGERPRINT)
    assert v.basis == "other_design" and v.intervals.calibration is None and v.intervals.p_consistent is None
    assert v.intervals.p_reject == pytest.approx(_cdf(45, 52, 0.9), rel=1e-9) and v.intervals.verdict is None
    assert v.within["K"].p_reject == pytest.approx(_cdf(16, 26, 0.9), rel=1e-9)
    assert _cdf(16, 26, 0.9) == pytest.approx(1.17e-4, rel=0.01)
    assert v.estimates is None  # a correct chain's share at this design is not known: grey
    page = truth_verdicts_html(v, run)
    assert (
        "<b>Recovering the truth</b> (3 synthetic subjects, 26 joint fits, 1 failed): the calibration run of "
        "2026-12-01 (102 fits) is of another design (fingerprint fedcba9876543210; this run 0123456789abcdef): this "
        "run's own counts, too few to decide unless they reject the target (p &lt; 0.001)." in page
    )
    assert "<b>Intervals: too few fits to decide</b>: this run " in page
    assert "/52 (87 %), target 90–98 %, not rejected (p = " in page
    assert "<b>Estimates outside tolerance in this run</b>" not in page  # the fallback names the run, not the design
    assert "<b>Estimates: too few fits to decide</b>: this run K " in page and "target ≥ 90 % (p = " in page
    assert "without a calibration of this design a correct chain's share is not known" in page
    # this run's own counts within the target: grey too
    fine = truth_verdicts(CORRECT, _calibration(95, (93, 93), fingerprint=OTHER), FINGERPRINT)
    assert fine.intervals.verdict is None and fine.estimates is None and fine.within["K"].p_reject == 1.0
    assert "<b>Estimates: too few fits to decide</b>" in truth_verdicts_html(fine, CORRECT)


def test_without_a_calibration_the_page_says_none_is_named():
    v = truth_verdicts(CORRECT, None, FINGERPRINT)
    assert v.basis == "none" and v.intervals.verdict is None
    assert "no calibration run named (report.calibration): this run's own counts, too few to decide" in (
        truth_verdicts_html(v, CORRECT)
    )


def test_this_run_alone_rejects_intervals_too_wide_at_the_target_s_high_end():
    """All intervals holding the truth: P(X >= n | n, 0.98) = 0.98^n, 0.35 for 52 (grey) and 5.5e-6 for 600 (red)."""
    assert share_check(52, 52, (0.90, 0.98), None).p_reject == pytest.approx(0.98**52, rel=1e-9)
    assert share_check(52, 52, (0.90, 0.98), None).verdict is None
    wide = share_check(600, 600, (0.90, 0.98), None)
    assert wide.p_reject == pytest.approx(0.98**600, rel=1e-9) and wide.verdict is False


@pytest.mark.parametrize(
    "args, message",
    [
        ((5, 4, (0.9, 1.0), None), "n must be <= total = 4, got 5"),
        ((1, 4, (0.9, 1.0), (7, 6)), "the calibration's count must be <= its fits = 6, got 7"),
        ((1, 4, (0.9, 1.0), (0, 0)), "calibration fits must be an integer >= 1, got 0"),
    ],
)
def test_impossible_counts_are_refused(args, message):
    with pytest.raises(LoperInputError, match=f"^{message}$"):
        share_check(*args)
