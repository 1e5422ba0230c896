"""The front page's truth part as HTML: the truth verdicts (:mod:`loper_analysis.report.truth_verdict`) and the
truth-recovery table, beside the calibration run's shares when the verdicts rest on it.

* :func:`truth_verdicts_html` - the verdicts' lines (``<li>``): what they rest on, the intervals, the estimates;
* :func:`truth_table_html` - the table ``lf-truth-recovery``.

Numbers are written as :mod:`loper_analysis.report.html_format` writes them (``data-q``, ``data-v``). K in
N·m/rad, D in N·m·s/rad.
"""

from __future__ import annotations

import html
import math

import pandas as pd

from loper_analysis.constants import parameter_column
from loper_analysis.impedance.identification.across_subjects import TRUTH_TOLERANCE
from loper_analysis.report.calibration import Calibration
from loper_analysis.report.headline import PARAMETER_KINDS
from loper_analysis.report.html_format import count, decimals, g, mark, num, pct
from loper_analysis.report.truth_verdict import CONSISTENCY_P, REJECT_P, ShareCheck, TruthVerdicts

__all__ = ["RULE", "truth_table_html", "truth_verdicts_html"]


def _p(p: float, key: str) -> str:
    """``p = 0.07`` (two significant digits, at least two decimals); ``p < 0.0001`` below that."""
    if p is None or not math.isfinite(p):
        return "p = –"
    if p < 1e-4:
        return "p &lt; 0.0001"
    return f"p = {num(p, max(2, decimals([p], significant=2, most=4)), key)}"


def _share(n: int, total: int, key: str, more: str = "") -> str:
    """``45/52 (87 %)`` with the count in its span; ``more`` added inside the brackets (``87 %; ...``)."""
    return f"{count(n, key)}/{total} ({pct(n, total)}{'; ' + more if more else ''})"


def _interval(check: ShareCheck) -> str:
    low, high = check.calibration_interval
    return f"{100 * low:.0f}–{100 * high:.0f} %"


def _target(check: ShareCheck) -> str:
    low, high = check.target
    return f"≥ {100 * low:.0f} %" if high >= 1.0 else f"{100 * low:.0f}–{100 * high:.0f} %"


def _basis_line(v: TruthVerdicts, who: str) -> str:
    """What the verdicts rest on: the calibration run (its date, size and seed) or this run alone."""
    c = v.calibration
    alone = f"this run's own counts, too few to decide unless they reject the target (p &lt; {REJECT_P:g})"
    if v.basis == "calibration":
        said = (
            f"verdict from the calibration run of {html.escape(c.date)}, "
            f"{count(c.n_subject_onset_fits, 'verdict|calibration|n_subject_onset_fits')} fits "
            f"({count(c.n_subjects, 'verdict|calibration|n_subjects')} subjects, seed {c.seed}), design fingerprint "
            "matches this run"
        )
    elif v.basis == "other_design":
        said = (
            f"the calibration run of {html.escape(c.date)} ({c.n_subject_onset_fits} fits) is of another design "
            f"(fingerprint {html.escape(c.design_fingerprint)}; this run {html.escape(v.fingerprint)}): {alone}"
        )
    else:
        said = f"no calibration run named (report.calibration): {alone}"
    return f"<li>{mark(None)}<b>Recovering the truth</b> ({who}): {said}.</li>"


def _intervals_line(check: ShareCheck) -> str:
    """The intervals' verdict: the calibration's share and this run's, or this run's alone."""
    if check.verdict:
        title = "Intervals hold the truth"
    elif check.verdict is None:
        title = "Intervals: too few fits to decide"
    elif check.calibration is not None and check.p_consistent >= CONSISTENCY_P:
        title = "Intervals miss the target at this design"
    else:
        title = "Intervals miss the truth in this run"
    run = _share(check.n, check.total, "verdict|truth|n_truth_in_ci95")
    if check.calibration is None:
        judged = "rejected" if check.verdict is False else "not rejected"
        said = (
            f"this run {run}, target {_target(check)}, {judged} ({_p(check.p_reject, 'verdict|truth|p_reject_ci95')})"
        )
    else:
        c_n, c_total = check.calibration
        agree = "agreeing" if check.p_consistent >= CONSISTENCY_P else "disagreeing"
        said = (
            f"calibration {_share(c_n, c_total, 'verdict|calibration|n_truth_in_ci95', _interval(check))}, target "
            f"{_target(check)}; this run {run}, {agree} ({_p(check.p_consistent, 'verdict|truth|p_consistent_ci95')})"
        )
    return f"<li>{mark(check.verdict)}<b>{title}</b>: {said}.</li>"


def _estimates_line(v: TruthVerdicts) -> str:
    """The estimates' verdict, K and D each: the calibration's shares and this run's, or this run's alone."""
    checks = v.within
    calibrated = v.basis == "calibration"
    off_here = any((c.p_consistent < CONSISTENCY_P) if calibrated else (c.verdict is False) for c in checks.values())
    design_met = all(c.target_met for c in checks.values())
    if v.estimates:
        title = "Estimates within tolerance" if design_met else "Estimates as a correct chain places them"
    elif v.estimates is None:
        title = "Estimates: too few fits to decide"
    else:
        title = "Estimates off the truth in this run"
    run = ", ".join(f"{p} {_share(c.n, c.total, f'verdict|truth|{p}_n_within_tolerance')}" for p, c in checks.items())
    target = _target(next(iter(checks.values())))
    if not calibrated:
        ps = ", ".join(_p(c.p_reject, f"verdict|truth|{p}_p_reject_within") for p, c in checks.items())
        said = (
            f"this run {run}, target {target} ({ps}); without a calibration of this design a correct chain's share "
            "is not known"
        )
    else:
        cal = ", ".join(
            f"{p} {_share(*c.calibration, f'verdict|calibration|{p}_n_within_tolerance', _interval(c))}"
            for p, c in checks.items()
        )
        ps = ", ".join(_p(c.p_consistent, f"verdict|truth|{p}_p_consistent_within") for p, c in checks.items())
        design = "" if design_met else " (this design's precision misses it)"
        said = (
            f"calibration {cal}, target {target}{design}; this run {run}, "
            f"{'disagreeing' if off_here else 'agreeing'} ({ps})"
        )
    return f"<li>{mark(v.estimates)}<b>{title}</b>: {said}.</li>"


#: The rule of the verdicts, as the note under the truth-recovery table states it.
RULE = (
    f"Verdicts on the truth: intervals ✓ when the calibration run's share meets the target (its binomial 95 % interval "
    f"reaches it) and this run's count agrees with that share (two-sided binomial p ≥ {CONSISTENCY_P:g}), ✗ otherwise; "
    "estimates ✓ when this run's counts agree with the calibration's (the design's share stated against its target), "
    "✗ otherwise; without a calibration of this run's design, this run's own counts: ● unless the intervals' reject "
    f"their target (one-sided binomial p &lt; {REJECT_P:g}: ✗). Intervals: K and D of every fit pooled; estimates: K "
    "and D each."
)


def truth_verdicts_html(verdicts: TruthVerdicts, truth: pd.DataFrame) -> str:
    """The truth verdicts as ``<li>`` lines: what they rest on, the intervals, the estimates.

    Parameters
    ----------
    verdicts : TruthVerdicts
        :func:`loper_analysis.report.truth_verdict.truth_verdicts` of ``truth``.
    truth : pandas.DataFrame
        :func:`loper_analysis.report.headline.truth_recovery` of the run (its subjects, fits and failures).

    Returns
    -------
    str
        The lines; one line saying so when no joint was fitted.
    """
    n_fits = int(truth["n_fits"].sum())
    n_failed = int(truth["n_failed"].sum())
    n_subjects = int(truth["n_subjects"].max()) if len(truth) else 0
    failed = f", {n_failed} failed" if n_failed else ""
    who = f"{n_subjects} synthetic subject{'s' if n_subjects != 1 else ''}, {n_fits} joint fits{failed}"
    if n_fits == 0:
        return f"<li>{mark(None)}<b>Recovering the truth</b> ({who}): no joint fitted.</li>"
    return _basis_line(verdicts, who) + _intervals_line(verdicts.intervals) + _estimates_line(verdicts)


def _calibration_cells(calibration: Calibration | None, p: str, joint: str) -> str:
    """The calibration's shares of a joint's parameter: within tolerance and truth in the CI (%)."""
    if calibration is None:
        return ""
    row = calibration.row(joint, p)
    if row is None:
        return '<td class="lf-dim">–</td><td class="lf-dim">–</td>'
    key = f"calibration|{p}_{joint}|"
    within = 100.0 * row.n_within_tolerance / row.n_fits
    inside = 100.0 * row.n_truth_in_ci95 / row.n_fits
    return (
        f'<td class="lf-dim">{num(within, 0, key + "within_tolerance_pct")} %</td>'
        f'<td class="lf-dim">{num(inside, 0, key + "truth_in_ci95_pct")} %</td>'
    )


def truth_table_html(truth: pd.DataFrame, calibration: Calibration | None = None) -> str:
    """Bias, median |error|, within tolerance and truth inside the CI, per parameter and joint.

    Parameters
    ----------
    truth : pandas.DataFrame
        :func:`loper_analysis.report.headline.truth_recovery` of the run.
    calibration : Calibration or None
        The calibration the verdicts rest on: its shares within tolerance and with the truth in the CI beside
        this run's counts; None: none (no such columns).

    Returns
    -------
    str
        The table ``lf-truth-recovery`` and its note.
    """
    body = []
    for p in PARAMETER_KINDS:
        bias, median = parameter_column(p, "error_mean"), parameter_column(p, "error_median_abs")
        share, within, inside = f"{p}_error_median_abs_pct", f"{p}_n_within_tolerance", f"{p}_n_truth_in_ci95"
        d = decimals(truth[[bias, median]].to_numpy().ravel())
        for k, r in enumerate(truth.to_dict("records")):
            key = f"truth-recovery|{p}_{r['joint']}|"
            n = r["n_fits"]
            sep = ' class="lf-sep"' if k == 0 and body else ""
            body.append(
                f'<tr{sep}><td class="lf-l">{p}<sub>{html.escape(str(r["joint"]))}</sub></td>'
                f"<td>{count(n, key + 'n_fits')}</td>"
                f"<td>{num(r[bias], d, key + bias)}</td>"
                f'<td>{num(r[median], d, key + median)} <span class="lf-dim">({num(r[share], 0, key + share)} %)'
                "</span></td>"
                f"<td>{count(r[within], key + within)}/{n}</td>"
                f"<td>{count(r[inside], key + inside)}/{n}</td>"
                f"{_calibration_cells(calibration, p, str(r['joint']))}</tr>"
            )
    (k_rel, k_abs), (d_rel, d_abs) = TRUTH_TOLERANCE["K"], TRUTH_TOLERANCE["D"]
    extra, said = "", f" {RULE}"
    if calibration is not None:
        extra = '<th class="lf-dim">calibration<br>within tol.</th><th class="lf-dim">calibration<br>truth in CI</th>'
        said += (
            f" Calibration: the shares of the calibration run of {html.escape(calibration.date)} "
            f"({html.escape(calibration.mode)} level, {html.escape(calibration.code_version)}, design fingerprint "
            f"{html.escape(calibration.design_fingerprint)})."
        )
    return (
        '<table id="lf-truth-recovery"><caption>Truth recovery: estimate − truth</caption>'
        '<thead><tr><th class="lf-l"></th><th>fits</th><th>mean<br>error</th><th>median |error|<br>'
        '<span class="lf-dim">(% of truth)</span></th><th>within<br>tolerance</th><th>truth in<br>95 % CI</th>'
        f"{extra}</tr></thead><tbody>{''.join(body)}</tbody></table>"
        '<p class="lf-note">Synthetic subjects, over subjects and onsets; K in N·m/rad, D in N·m·s/rad. '
        f"Tolerance: {k_rel * 100:g} % of the truth or {g(k_abs)} N·m/rad for K, {d_rel * 100:g} % or "
        f"{g(d_abs)} N·m·s/rad for D. Fits: status ok or not identifiable.{said}</p>"
    )
