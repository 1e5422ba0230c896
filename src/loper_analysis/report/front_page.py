"""The front page of the Snakemake report: what was run, the headline numbers and the main figure, as HTML.

Renders the headline tables of :mod:`loper_analysis.report.headline` (as the file
step :func:`loper_analysis.stages.report.step.front_page` computes them from the
result tables) into one HTML fragment, which ``workflow/report/workflow.rst``
pulls into the report's "Workflow" panel above the methods text:

* :class:`RunSettings` - the run's settings, as the page lists them;
* :func:`front_page_html` - the fragment. Its tables carry the ids
  ``lf-impedance-summary``, ``lf-truth-recovery``, ``lf-transparency``,
  ``lf-device`` and ``lf-run``, the figure ``lf-figure``.

Every number the fragment shows sits in a ``<span>`` whose ``data-q`` names
its table, row and column (``table|row|column``) and whose ``data-v`` holds
the value at full precision (``repr``), so the page can be checked against
the tables (:mod:`loper_analysis.report.html_format`). The truth verdicts and
the truth-recovery table are :mod:`loper_analysis.report.truth_page`'s, on the
rule of :mod:`loper_analysis.report.truth_verdict`. The fragment holds no time, host or path: the same tables,
settings, versions and figure give the same bytes. K in N·m/rad, D in
N·m·s/rad, angles in rad.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import pandas as pd

from loper_analysis.constants import PARAMETER_UNITS, parameter_column
from loper_analysis.errors import LoperInputError
from loper_analysis.reference import STUDY_SWING_IMPEDANCE
from loper_analysis.report.calibration import Calibration
from loper_analysis.report.headline import PARAMETER_KINDS
from loper_analysis.report.html_format import count as _count
from loper_analysis.report.html_format import decimals as _decimals
from loper_analysis.report.html_format import g as _g
from loper_analysis.report.html_format import mark as _mark
from loper_analysis.report.html_format import num as _num
from loper_analysis.report.truth_page import truth_table_html, truth_verdicts_html
from loper_analysis.report.truth_verdict import truth_verdicts

__all__ = [
    "SOFTWARE",
    "RunSettings",
    "front_page_html",
]

#: Software the front page lists: label -> distribution name (Python itself is listed first).
SOFTWARE: dict[str, str] = {
    "loper_analysis": "loper-analysis",
    "OpenSim": "opensim",
    "ezc3d": "ezc3d",
    "NumPy": "numpy",
    "SciPy": "scipy",
    "pandas": "pandas",
    "Snakemake": "snakemake",
}

#: Unit of each parameter kind, as the page writes it.
_UNIT = {p: PARAMETER_UNITS[f"{p}_hip"] for p in PARAMETER_KINDS}


# ---------------------------------------------------------------------------------------------- the run


@dataclass(frozen=True)
class RunSettings:
    """The settings of a run the front page lists (the workflow's configuration; units in the names)."""

    seed: int
    perturbation_onsets_ms: Sequence[int]
    perturbation_repeats: int
    perturbed_side: str
    filter_cutoff_hz: float
    filter_order: int
    window_before_s: float
    window_after_s: float
    stiffness_bounds_nm_per_rad: Sequence[float]
    damping_bounds_nms_per_rad: Sequence[float]
    n_starts: int
    noise_model: str
    null_pair_components: int
    synthetic_variability: str
    synthetic_walking_duration_s: float
    pulse_force_n: float
    pulse_duration_s: float

    def rows(self) -> list[tuple[str, str]]:
        """(label, value) of every setting, as the page shows them."""
        onsets = ", ".join(str(int(o)) for o in self.perturbation_onsets_ms)
        k_lo, k_hi = self.stiffness_bounds_nm_per_rad
        d_lo, d_hi = self.damping_bounds_nms_per_rad
        noise = (
            f"null pairs ({self.null_pair_components} deviation shapes projected out)"
            if self.noise_model == "null_pairs"
            else f"{self.noise_model} (plain least squares)"
        )
        return [
            (
                "perturbations",
                f"onsets {onsets} ms after {self.perturbed_side} toe-off, {self.perturbation_repeats} trials per onset",
            ),
            (
                "fit window",
                f"{_g(self.window_before_s * 1000)} ms before to {_g(self.window_after_s * 1000)} ms after onset",
            ),
            (
                "bounds",
                f"K {_g(k_lo)}–{_g(k_hi)} N·m/rad, D {_g(d_lo)}–{_g(d_hi)} N·m·s/rad; {self.n_starts} random starts",
            ),
            ("noise model", noise),
            ("filter", f"Butterworth low-pass {_g(self.filter_cutoff_hz)} Hz, order {self.filter_order}, zero phase"),
            (
                "synthetic lab",
                f"{_g(self.synthetic_walking_duration_s)} s per walking trial, pulses of "
                f"{_g(self.pulse_force_n)} N for {_g(self.pulse_duration_s * 1000)} ms, "
                f"variability '{self.synthetic_variability}'",
            ),
            ("seed", str(self.seed)),
        ]


def _subject_line(subjects: Mapping[str, str], trials: Mapping[str, Sequence[str]]) -> str:
    """'3 synthetic (S01, S02, S03) + 0 recorded subjects, 8 walking trials each' (HTML)."""
    parts = []
    for source in ("synthetic", "recorded"):
        names = [s for s, src in subjects.items() if src == source]
        listed = f" ({html.escape(', '.join(names))})" if names else ""
        parts.append(f"{len(names)} {source}{listed}")
    counts = sorted({len(t) for t in trials.values()})
    if not counts:
        per = "no walking trials processed"
    elif len(counts) == 1:
        per = f"{counts[0]} walking trials each"
    else:
        per = f"{counts[0]}–{counts[-1]} walking trials per subject"
    return f"{parts[0]} + {parts[1]} subjects, {per}"


#: The fragment's style: every rule under ``.lf`` but the first, which top-aligns the report's content pane while
#: it holds the front page (Snakemake centres it vertically, so a Workflow panel taller than the screen would
#: lose its top, out of reach of the scroll bar).
_STYLE = """<style>
.h-screen.overflow-auto.items-center:has(.lf){align-items:flex-start}
.lf{font-size:12.5px;line-height:1.4;color:#1f2937;margin:0 0 10px}
.lf h2{font-size:14px;font-weight:700;margin:10px 0 3px;line-height:1.3;color:#111827}
.lf p{margin:2px 0 4px}
.lf ul.lf-verdicts{list-style:none;padding:0;margin:2px 0 6px}
.lf ul.lf-verdicts li{margin:1px 0;padding:0 0 0 18px;text-indent:-18px}
.lf .lf-mark{display:inline-block;width:18px;text-indent:0;text-align:center}
.lf table{border-collapse:collapse;margin:2px 0 8px;font-size:12px;line-height:1.3;width:auto}
.lf th,.lf td{padding:1px 5px;text-align:right;border:0;border-bottom:1px solid #e5e7eb;white-space:nowrap;
 font-variant-numeric:tabular-nums;vertical-align:baseline}
.lf thead th{font-weight:600;color:#374151;border-bottom:1px solid #9ca3af;vertical-align:bottom}
.lf .lf-l{text-align:left}
.lf caption{caption-side:top;text-align:left;font-weight:700;font-size:12.5px;padding:0 0 1px;color:#111827}
.lf .lf-ok{color:#15803d;font-weight:700}
.lf .lf-bad{color:#b91c1c;font-weight:700}
.lf .lf-dim,.lf .lf-note{color:#6b7280}
.lf .lf-note{font-size:11px;margin:0 0 6px}
.lf tr.lf-sep td{border-top:1px solid #9ca3af}
.lf img{max-width:100%;height:auto;margin:4px 0 2px}
.lf h3{font-size:13px;font-weight:700;margin:8px 0 2px}
.lf img.lf-wide{max-width:760px}
.lf td.lf-wrap{white-space:normal;max-width:360px}
.lf ul.lf-warnings{color:#b91c1c;margin:2px 0 6px;padding-left:18px}
</style>"""


# ------------------------------------------------------------------------------------------ the sections


def _summary_table(ci: pd.DataFrame) -> str:
    """Across-subject mean [95 % CI] of K and D, VAF and counts, per joint and onset."""
    dec = {}
    for p in PARAMETER_KINDS:
        cols = [parameter_column(p, w) for w in ("mean", "ci95_low", "ci95_high")]
        for joint in set(ci["joint"]):
            dec[p, joint] = _decimals(ci.loc[ci["joint"] == joint, cols].to_numpy().ravel())
    body = []
    for joint, g in ci.groupby("joint", sort=False):
        for k, r in enumerate(g.to_dict("records")):
            key = f"impedance-summary|{joint}|{r['onset_ms']}|"
            cells = [
                f'<td class="lf-l" rowspan="{len(g)}">{html.escape(str(joint))}</td>' if k == 0 else "",
                f"<td>{_count(r['onset_ms'], key + 'onset_ms')}</td>",
            ]
            for p in PARAMETER_KINDS:
                d = dec[p, joint]
                mean, low, high = (parameter_column(p, w) for w in ("mean", "ci95_low", "ci95_high"))
                interval = f"[{_num(r[low], d, key + low)}, {_num(r[high], d, key + high)}]"
                cells.append(f'<td>{_num(r[mean], d, key + mean)} <span class="lf-dim">{interval}</span></td>')
            if k == 0:
                study = STUDY_SWING_IMPEDANCE.get(joint)
                text = (
                    f"K {_g(study['K'][0])}–{_g(study['K'][1])}<br>D {_g(study['D'][0])}–{_g(study['D'][1])}"
                    if study
                    else "–"
                )
                cells.append(f'<td class="lf-dim" rowspan="{len(g)}">{text}</td>')
            cells.append(f"<td>{_num(r['vaf_pct_mean'], 0, key + 'vaf_pct_mean')}</td>")
            n = _count(r["n_subjects"], key + "n_subjects")
            if r["n_not_identifiable"]:
                n += f' <span class="lf-dim">({_count(r["n_not_identifiable"], key + "n_not_identifiable")})</span>'
            cells.append(f"<td>{n}</td>")
            sep = ' class="lf-sep"' if k == 0 and body else ""
            body.append(f"<tr{sep}>{''.join(cells)}</tr>")
    return (
        '<table id="lf-impedance-summary"><caption>Impedance: across-subject mean [95 % CI]</caption>'
        '<thead><tr><th class="lf-l">joint</th><th>onset<br>ms</th><th>K<br>N·m/rad</th><th>D<br>N·m·s/rad</th>'
        '<th>study<br><span class="lf-dim">over onsets</span></th>'
        '<th>VAF<br>%</th><th>subjects<br><span class="lf-dim">(not ident.)</span></th></tr></thead>'
        f"<tbody>{''.join(body)}</tbody></table>"
        '<p class="lf-note">Onset after toe-off. Mean and CI: random effects, each subject weighted by its fit’s '
        "standard error and the spread between subjects (Hartung–Knapp, t on n − 1 df). “Not ident.”: fits whose "
        "CI holds 0 and the plausible range, or is wider than that range (in the mean). Study: the range of its "
        "across-subject means over "
        "onsets.</p>"
    )


def _transparency_table(tr: pd.DataFrame) -> str:
    """Group RMSD against ISV_ave per phase and joint, with the study's values."""
    d = 3
    body = []
    for r in tr.to_dict("records"):
        key = f"transparency|{r['phase']}|{r['joint']}|"
        study = (
            f"{_num(r['study_rmsd_rad'], d, key + 'study_rmsd_rad')} / "
            f"{_num(r['study_isv_ave_rad'], d, key + 'study_isv_ave_rad')}"
        )
        body.append(
            f'<tr><td class="lf-l">{html.escape(str(r["phase"]))}</td>'
            f'<td class="lf-l">{html.escape(str(r["joint"]))}</td>'
            f"<td>{_num(r['rmsd_rad'], d, key + 'rmsd_rad')}</td>"
            f"<td>{_num(r['isv_ave_rad'], d, key + 'isv_ave_rad')}</td>"
            f"<td>{_mark(r['transparent'])}</td>"
            f"<td>{_count(r['n_subjects_transparent'], key + 'n_subjects_transparent')}/{r['n_subjects']}</td>"
            f'<td class="lf-dim">{study}</td></tr>'
        )
    return (
        '<table id="lf-transparency"><caption>Transparency: RMSD with vs without the device (rad)'
        '</caption><thead><tr><th class="lf-l">phase</th><th class="lf-l">joint</th><th>RMSD</th><th>ISV_ave</th>'
        "<th>RMSD &lt;<br>ISV_ave</th><th>subjects</th><th>study<br>RMSD / ISV_ave</th></tr></thead>"
        f"<tbody>{''.join(body)}</tbody></table>"
    )


#: How the device table names the study's metrics.
_DEVICE_NAMES = {
    "bandwidth_hz": "−3 dB bandwidth",
    "rise_time_ms": "rise time 10–90 %",
    "overshoot_pct": "overshoot",
    "steady_state_40n_n": "steady state, 40 N steps",
}


def _device_table(dev: pd.DataFrame) -> str:
    """Our device figures beside the study's."""
    body = []
    for r in dev.to_dict("records"):
        key = f"device|{r['metric']}|"
        body.append(
            f'<tr><td class="lf-l">{html.escape(_DEVICE_NAMES.get(r["metric"], r["metric"]))}</td>'
            f"<td>{_num(r['value'], 1, key + 'value')}</td>"
            f"<td>{_num(r['study_value'], 1, key + 'study_value')}</td>"
            f'<td class="lf-l">{html.escape(r["unit"])}</td>'
            f"<td>{_num(r['difference_pct'], 1, key + 'difference_pct')}</td></tr>"
        )
    return (
        '<table id="lf-device"><caption>Device: force controller, free-hanging leg</caption>'
        '<thead><tr><th class="lf-l"></th><th>ours</th><th>study</th><th></th><th>difference<br>%</th></tr>'
        f"</thead><tbody>{''.join(body)}</tbody></table>"
    )


# ------------------------------------------------------------------------------------------------ verdicts


def _transparency_verdict_line(tr: pd.DataFrame) -> str:
    """'✓ Transparent: RMSD < ISV_ave in 6/6 phase × joint, 18/18 per subject'."""
    judged = [v for v in tr["transparent"] if v is not None]
    n_ok = int(sum(judged))
    ok = None if not judged else n_ok == len(judged)
    word = "Transparent" if ok else ("Not transparent everywhere" if ok is False else "Transparency not judged")
    subjects = (
        f"{_count(int(tr['n_subjects_transparent'].sum()), 'verdict|transparency|n_subjects_transparent')}"
        f"/{int(tr['n_subjects'].sum())}"
    )
    return (
        f"<li>{_mark(ok)}<b>{word}</b>: RMSD &lt; ISV_ave in "
        f"{_count(n_ok, 'verdict|transparency|n_transparent')}/{len(tr)} phase × joint, {subjects} per "
        f"subject.</li>"
    )


def _device_verdict_line(dev: pd.DataFrame) -> str:
    """'● Device as in the study: 4 figures within 3.4 %; bandwidth 38.8 Hz (study 39)'."""
    worst = float(dev["difference_pct"].abs().max())
    band = dev[dev["metric"] == "bandwidth_hz"]
    bandwidth = ""
    if len(band):
        bandwidth = (
            f"; bandwidth {_num(band['value'].iloc[0], 1, 'verdict|device|bandwidth_hz')} Hz "
            f"(study {_g(band['study_value'].iloc[0])})"
        )
    return (
        f"<li>{_mark(None)}<b>Device</b> as in the study: {len(dev)} figures within "
        f"{_num(worst, 1, 'verdict|device|max_abs_difference_pct')} %{bandwidth}.</li>"
    )


def _validation_verdict_line(val: pd.DataFrame) -> str:
    """'✓ Validation without noise (729 combinations): |error| ≤ 0.035 N·m/rad ... (study ≤ 0.87 ...)'."""
    ok = bool(val["within_study"].all())
    parts, study = [], []
    for r in val.to_dict("records"):
        p = r["parameter"]
        worst = max(abs(r["min_error"]), abs(r["max_error"]))
        d = _decimals([worst], significant=2, most=6)
        parts.append(f"{_num(worst, d, 'verdict|validation|' + p + '_max_abs_error')} {_UNIT[p]} ({p})")
        study.append(_g(max(abs(r["study_min_error"]), abs(r["study_max_error"]))))
    n = int(val["n_combinations"].min())
    return (
        f"<li>{_mark(ok)}<b>Validation</b> without noise ({n} combinations): |error| ≤ {', '.join(parts)}; "
        f"the study ≤ {' and '.join(study)}.</li>"
    )


# ------------------------------------------------------------------------------------------------ the page


def front_page_html(
    subjects: Mapping[str, str],
    trials: Mapping[str, Sequence[str]],
    settings: RunSettings,
    versions: Mapping[str, str],
    device: pd.DataFrame,
    validation: pd.DataFrame | None,
    *,
    summary: pd.DataFrame | None = None,
    truth: pd.DataFrame | None = None,
    impedance_status: Mapping[str, int] | None = None,
    figure_png: bytes | None = None,
    transparency: pd.DataFrame | None = None,
    recorded_html: str = "",
    calibration: Calibration | None = None,
    design_fingerprint: str = "",
) -> str:
    """The front page as one HTML fragment (a ``<style>`` and a ``<div class="lf">``).

    Parameters
    ----------
    subjects : Mapping[str, str]
        Subject -> ``synthetic`` or ``recorded``, in the subject sheet's order.
    trials : Mapping[str, Sequence[str]]
        Processed subject -> its walking trials.
    settings : RunSettings
        The run's settings.
    versions : Mapping[str, str]
        Software -> version, in the order to show (Python and :data:`SOFTWARE`).
    device : pandas.DataFrame
        :func:`~loper_analysis.report.headline.device_comparison`.
    validation : pandas.DataFrame or None
        :func:`~loper_analysis.report.headline.validation_verdict`; None: no validation study (a study without
        perturbation trials).
    summary : pandas.DataFrame or None
        :func:`~loper_analysis.report.headline.impedance_summary_ci`; None: the run had no perturbation trials.
    truth : pandas.DataFrame or None
        :func:`~loper_analysis.report.headline.truth_recovery`; None or no rows: no subject with a known truth.
    impedance_status : Mapping[str, int] or None
        Status -> number of rows of the impedance table (shown when nothing was fitted).
    figure_png : bytes or None
        The main figure (``results/impedance/impedance.png``), embedded as a data URI.
    transparency : pandas.DataFrame or None
        :func:`~loper_analysis.report.headline.transparency_verdict`; None: no subject walked both trials of the
        transparency pair.
    recorded_html : str
        The section on recorded subjects (:func:`loper_analysis.report.subject_quality.recorded_subjects_html`),
        placed after the impedance results.
    calibration : Calibration or None
        The calibration run the truth verdicts rest on when it is of this run's design
        (:func:`loper_analysis.report.calibration.calibration_from_table`); None: none named, the verdicts rest on
        this run's own counts (:func:`loper_analysis.report.truth_verdict.truth_verdicts`).
    design_fingerprint : str
        This run's design fingerprint (:func:`loper_analysis.report.calibration.design_fingerprint`).

    Returns
    -------
    str
        The fragment, ending in a newline. It holds no time, host or path.
    """
    if not isinstance(settings, RunSettings):
        raise LoperInputError(f"settings must be a RunSettings, got {type(settings).__name__}")
    parts = [_STYLE, '<div class="lf">']
    onsets = ", ".join(str(int(o)) for o in settings.perturbation_onsets_ms)
    design = (
        f" (onsets {onsets} ms × {settings.perturbation_repeats} + the transparency pair)"
        if summary is not None
        else ""
    )
    parts.append(
        f"<p><b>Run</b>: {_subject_line(subjects, trials)}{design}; seed {settings.seed}; settings and "
        "versions at the end.</p>"
    )
    has_truth = truth is not None and len(truth) > 0
    verdicts = truth_verdicts(truth, calibration, design_fingerprint) if has_truth else None
    truth_lines = truth_verdicts_html(verdicts, truth) if has_truth else ""
    parts.append(_verdict_list(truth_lines, transparency, device, validation))
    if summary is None:
        parts.append("<p>No perturbation trials in this run: no impedance was identified.</p>")

    elif not len(summary):
        status = ", ".join(f"{n} {html.escape(s)}" for s, n in (impedance_status or {}).items())
        parts.append(
            f'<p id="lf-impedance-summary"><b>Impedance</b>: no joint was fitted '
            f"({status or 'no rows'}; the reasons are in results/impedance/impedance.tsv).</p>"
        )
    else:
        parts.append(_summary_table(summary))
    if has_truth and truth["n_fits"].sum() > 0:
        parts.append(truth_table_html(truth, calibration if verdicts.basis == "calibration" else None))
    if figure_png:
        data = base64.b64encode(figure_png).decode("ascii")
        parts.append(
            "<h2>K and D per onset</h2>"
            f'<img id="lf-figure" alt="Stiffness K and damping D per onset: subjects, mean and truth" '
            f'src="data:image/png;base64,{data}">'
            '<p class="lf-note">Grey: each subject; black: the across-subject mean; open circles: the '
            "truth of synthetic subjects.</p>"
        )
    if recorded_html:
        parts.append(recorded_html)
    if transparency is not None and len(transparency):
        parts.append(_transparency_table(transparency))
    if len(device):
        parts.append(_device_table(device))
    parts.append(_run_table(subjects, trials, settings, versions, summary is None))
    parts.append("</div>")
    return "\n".join(parts) + "\n"


def _verdict_list(
    truth_lines: str,
    transparency: pd.DataFrame | None,
    device: pd.DataFrame,
    validation: pd.DataFrame | None,
) -> str:
    """The verdicts (``<ul class="lf-verdicts">``): truth recovery (``truth_lines``, from
    :func:`loper_analysis.report.truth_page.truth_verdicts_html`), transparency, device and validation, each when
    there is something to judge."""
    verdicts = [truth_lines] if truth_lines else []
    if transparency is not None and len(transparency):
        verdicts.append(_transparency_verdict_line(transparency))
    if len(device):
        verdicts.append(_device_verdict_line(device))
    if validation is not None and len(validation):
        verdicts.append(_validation_verdict_line(validation))
    return f'<ul class="lf-verdicts">{"".join(verdicts)}</ul>'


def _run_table(
    subjects: Mapping[str, str],
    trials: Mapping[str, Sequence[str]],
    settings: RunSettings,
    versions: Mapping[str, str],
    no_perturbations: bool,
) -> str:
    """The table of what was run: subjects, settings and software versions (a study without perturbation
    trials: without the fit's settings)."""
    shown = settings.rows()
    if no_perturbations:  # no fit settings, and a synthetic lab only with its subjects
        skip = {"perturbations", "fit window", "bounds", "noise model"}
        if "synthetic" not in subjects.values():
            skip.add("synthetic lab")
        shown = [(k, v) for k, v in shown if k not in skip]
    rows = "".join(
        f'<tr><td class="lf-l">{html.escape(k)}</td><td class="lf-l">{html.escape(v)}</td></tr>' for k, v in shown
    )
    software = " · ".join(f"{html.escape(k)} {html.escape(v)}" for k, v in versions.items())
    return (
        '<table id="lf-run"><caption>What was run</caption><tbody>'
        f'<tr><td class="lf-l">subjects</td><td class="lf-l">{_subject_line(subjects, trials)}</td></tr>'
        f'{rows}<tr><td class="lf-l">software</td><td class="lf-l" style="white-space:normal">'
        f"{software}</td></tr></tbody></table>"
    )
