"""The report stage's files: its result files (name -> pattern under ``results/report/``) and the tables the front
page and the Markdown rendering read (the calibration table of the truth verdicts where the configuration names
it, ``report.calibration``)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "front_page_inputs", "recorded_quality_files", "targets"]

FILES: dict[str, str] = {
    "tables": "tables.md",
    "front_page": "front_page.html",
}


def recorded_quality_files(study: Study) -> dict:
    """The files of the front page's section on recorded subjects: per recorded subject its scale report
    (None with a model from the sheet) and per walking trial its IK summary, agreement with the lab's own
    angles and figures (the force plates' None without plates)."""
    p, out, scaled = study.paths, {}, set(study.scaled_subjects())
    for s in study.processed_subjects():
        if study.source(s) != "recorded":
            continue
        trials = {
            t: {
                "ik": fill(p.ik.summary, subject=s, trial=t),
                "agreement": fill(p.ik.agreement, subject=s, trial=t),
                "angles_png": fill(p.strides.figure, subject=s, trial=t),
                "grf_png": fill(p.grf.figure, subject=s, trial=t) if study.has_force_platforms(s, t) else None,
            }
            for t in study.subject_trials(s)
        }
        scale = fill(p.model.scale, subject=s) if s in scaled else None
        out[s] = {"scale": scale, "trials": trials}
    return out


def front_page_inputs(study: Study) -> dict:
    """The tables the front page reads, named as the fields of ``FrontPageFiles``: the validation and device
    summaries when built, the impedance tables and main figure with perturbation trials, the calibration table
    of the truth verdicts (``report.calibration``) with perturbation trials of a synthetic subject, the
    transparency table with a subject who walked both trials, the recorded subjects' quality files."""
    p = study.paths
    out = {"validation": p.validation.summary} if study.has_validation() else {}
    if study.has_device_tests():
        out["device"] = p.device.summary
    if study.identifies_impedance():
        out.update(impedance=p.impedance.table, summary=p.impedance.summary, figure=p.impedance.figure)
        calibration = study.settings["report"].calibration
        if calibration is not None and "synthetic" in map(study.source, study.processed_subjects()):
            out["calibration"] = calibration
    if study.transparency_subjects():
        out["rmsd"] = p.transparency.rmsd
    recorded = recorded_quality_files(study)
    if recorded:
        out["strides"] = p.strides.summary
        out["quality"] = [
            path
            for entry in recorded.values()
            for path in [entry["scale"], *(f for files in entry["trials"].values() for f in files.values())]
            if path is not None
        ]
    return out


def targets(study: Study) -> list[str]:
    """The Markdown rendering of the tables (with perturbation trials) and the front page."""
    r = study.paths.report
    return [*([r.tables] if study.identifies_impedance() else []), r.front_page]
