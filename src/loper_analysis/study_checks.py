"""The study's inputs checked before any job runs: the subject sheet's rows against the config and the raw
folders against the trial design."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from loper_analysis.errors import LoperInputError
from loper_analysis.io.raw_files import RAW_SUFFIXES, raw_file_present, refuse_miscased_raw_files, unmatched_raw_files
from loper_analysis.layout import Study, fill
from loper_analysis.synthetic.subjects import true_impedance

__all__ = ["check_subjects", "raw_file_warnings"]


def check_subjects(study: Study, sheet: str, source: Callable[..., str]) -> None:
    """Every subject's inputs before any work starts: a synthetic truth inside the identification bounds, a
    recorded subject's model_osim, static trial and height; a truth for every onset; the device subject.

    ``sheet``: the subject sheet's name; ``source(*keys)``: the file or option that set a config key.

    Raises
    ------
    LoperInputError
        Naming the sheet or the config file, the subject, the column or key and the value.
    """
    c, static = study.config, study.design.static
    for s, row in study.rows.items():
        c3d = fill(study.paths.raw.c3d, subject=s, trial=static)
        if row["source"] == "synthetic":  # the truth must lie inside the identification bounds
            synth, ident = c["synthetic"], c["identification"]
            true_impedance(
                s,
                c["seed"],
                synth["stiffness_nm_per_rad"],
                synth["damping_nms_per_rad"],
                synth["between_subject_cv"],
                ident["stiffness_bounds_nm_per_rad"],
                ident["damping_bounds_nms_per_rad"],
            )
        elif "model_osim" in row:  # an already scaled model: no static trial, no scaling
            if not Path(row["model_osim"]).is_file():
                raise LoperInputError(
                    f"{sheet}: subject '{s}', column model_osim: file '{row['model_osim']}' not found"
                )
        elif not raw_file_present(c3d, f"static trial of subject '{s}'"):
            raise LoperInputError(
                f"{sheet}: recorded subject '{s}' has no static trial {c3d} (raw files are named "
                f"{study.paths.raw.c3d}), nor a scaled model (column model_osim)"
            )
        elif c["opensim"]["generic_model"] is None and "height_m" not in row:
            raise LoperInputError(
                f"{sheet}: recorded subject '{s}' needs height_m: the generated model "
                f"({source('opensim', 'generic_model')}: opensim.generic_model null) is built from height "
                "(a lab's model, such as gait2392, needs none)"
            )
    onsets = {int(o) for o in c["synthetic"]["stiffness_nm_per_rad"]}
    missing = set(study.design.perturbation_onsets_ms) - onsets
    if any(r["source"] == "synthetic" for r in study.rows.values()) and missing:
        raise LoperInputError(
            f"{source('synthetic', 'stiffness_nm_per_rad')}: key 'synthetic.stiffness_nm_per_rad': no truth "
            f"for onset(s) {sorted(missing)} ms of trials.perturbation_onsets_ms"
        )
    device = c["device"]["subject"]
    if device is not None and device not in study.rows:
        raise LoperInputError(
            f"{source('device', 'subject')}: key 'device.subject': subject '{device}' is not in {sheet}"
        )


def raw_file_warnings(study: Study) -> list[str]:
    """Check every recorded subject's raw folder: a path that is not a readable file, or a file named in
    another case, stops the run (never a trial silently left out); returns a warning per folder naming the
    files that match no trial of the design.

    Raises
    ------
    LoperInputError
        Naming the file.
    """

    said, trials, t = [], study.design.trials(), study.config["trials"]
    for s in (s for s, row in study.rows.items() if row["source"] == "recorded"):
        raw = study.paths.raw_folder(s)
        for trial in trials:
            for suffix in RAW_SUFFIXES:
                raw_file_present(raw / f"{trial}{suffix}", f"raw file of trial '{trial}' of subject '{s}'")
        refuse_miscased_raw_files(raw, trials)
        unmatched = unmatched_raw_files(raw, trials)
        if unmatched:
            said.append(
                f"warning: {raw}: {', '.join(unmatched)}: no trial of the design has this name, not analysed "
                f"(trials: {', '.join(trials)}; from trials.static, trials.no_device, trials.device, "
                f"trials.perturbation_onsets_ms {t['perturbation_onsets_ms']} and trials.perturbation_repeats "
                f"{t['perturbation_repeats']})"
            )
    return said
