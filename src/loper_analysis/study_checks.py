"""The study's inputs checked before any job runs: the subject sheet's rows against the config, the raw
folders against the trial design, a synthetic subject's folder holding no recording the synthetic lab would write
over, no recording standing for two trials, and subject IDs short enough for the file names built from them."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import stage_name
from loper_analysis.io.generated import MANIFEST_SUFFIX, unvouched_files
from loper_analysis.io.raw_files import (
    RAW_SUFFIXES,
    raw_file_present,
    refuse_miscased_raw_files,
    repeated_files,
    unmatched_raw_files,
)
from loper_analysis.layout import RAW_FILES, Study, fill
from loper_analysis.schema import check_table
from loper_analysis.stages import RESULT_FILES, study_paths

__all__ = [
    "NAME_MAX",
    "SUBJECT_LOG_KEYS",
    "check_recordings",
    "check_subject_ids",
    "check_subject_sheet",
    "check_subjects",
    "subject_file_names",
    "subject_id_limit",
    "raw_file_warnings",
    "refuse_recordings_in_synthetic_folders",
    "refuse_repeated_recordings",
]


#: The most bytes a file or folder name holds: NAME_MAX of Linux and macOS, and NTFS's 255 UTF-16 units.
NAME_MAX = 255
#: The wildcards of the rules' logs and benchmarks that hold a subject (:meth:`Paths.log`, :meth:`Paths.benchmark`).
SUBJECT_LOG_KEYS: tuple[str, ...] = ("{subject}", "{subject}/{trial}", "{subject}/{trial}.{chunk}")
#: What a rule's log adds to its name for the job's profile (``{log}.prof``, :mod:`loper_analysis.stages.logs`).
PROFILE_SUFFIX = ".prof"


def subject_file_names() -> list[str]:
    """Every file or folder name built from a subject ID (``{subject}`` in it), longest first: the names of the
    raw and result patterns (:mod:`loper_analysis.layout`), the logs (and their profiles) and benchmarks, each also
    as the staging directory the writers create beside it (:func:`loper_analysis.io.atomic.stage_name`)."""
    paths = study_paths()
    patterns = [
        *(f"{paths.raw_dir}/{p}" for p in RAW_FILES.values()),
        *(f"{paths.results_dir}/{stage}/{p}" for stage, files in RESULT_FILES.items() for p in files.values()),
    ]
    for key in SUBJECT_LOG_KEYS:
        log = paths.log("rule", key)
        patterns += [log, log + PROFILE_SUFFIX, paths.benchmark("rule", key)]
    names = {part for pattern in patterns for part in pattern.split("/") if "{subject}" in part}
    return sorted(names | {stage_name(n) for n in names}, key=lambda n: (-len(n), n))


def subject_id_limit() -> tuple[int, str]:
    """The longest subject ID every name built from it fits (:data:`NAME_MAX` bytes), and the longest such name."""
    longest = subject_file_names()[0]
    return NAME_MAX - (len(longest.encode()) - len("{subject}")), longest


def check_subject_ids(subjects: pd.DataFrame, sheet: str) -> None:
    """Refuse a subject ID too long for the file names built from it (:func:`subject_id_limit`), before any job:
    the job would fail with the operating system's "File name too long".

    Raises
    ------
    LoperInputError
        Naming the sheet, the row (1-based, after the header), the ID's length and the limit.
    """
    if "subject" not in subjects.columns:
        return
    limit, longest = subject_id_limit()
    for n, subject in enumerate(subjects["subject"], start=1):
        length = len(str(subject).encode())
        if length > limit:
            raise LoperInputError(
                f"{sheet}: row {n}, column 'subject': the subject ID '{str(subject)[:24]}...' is {length} characters "
                f"long; at most {limit} fit: a file name holds at most {NAME_MAX} bytes and the longest one built "
                f"from an ID, '{longest}', adds {len(longest.encode()) - len('{subject}')}"
            )


def check_subject_sheet(subjects: pd.DataFrame, schema_path: str | Path, sheet: str) -> None:
    """Every row of the subject sheet against its schema (:func:`loper_analysis.schema.check_table`), the subject
    IDs' length first (:func:`check_subject_ids`: its message gives the length and the limit)."""
    check_subject_ids(subjects, sheet)
    check_table(subjects, schema_path, sheet)


def check_subjects(study: Study, sheet: str, source: Callable[..., str]) -> None:
    """Every subject's inputs before any work starts: a synthetic truth inside the identification bounds, a
    recorded subject's model_osim, static trial and height; a truth for every onset; the device subject.

    ``sheet``: the subject sheet's name; ``source(*keys)``: the file or option that set a config key.

    Raises
    ------
    LoperInputError
        Naming the sheet or the config file, the subject, the column or key and the value.
    """
    settings, static = study.settings, study.design.static
    truth = settings["synthetic"].truth
    for s, row in study.rows.items():
        c3d = fill(study.paths.raw.c3d, subject=s, trial=static)
        if row["source"] == "synthetic":  # the truth must lie inside the identification bounds
            truth.of(s, settings["study"].seed)
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
        elif settings["model"].generic_model is None and "height_m" not in row:
            raise LoperInputError(
                f"{sheet}: recorded subject '{s}' needs height_m: the generated model "
                f"({source('model', 'generic_model')}: model.generic_model null) is built from height "
                "(a lab's model, such as gait2392, needs none)"
            )
    onsets = {int(o) for o in truth.stiffness_nm_per_rad}
    missing = set(study.design.perturbation_onsets_ms) - onsets
    if any(r["source"] == "synthetic" for r in study.rows.values()) and missing:
        raise LoperInputError(
            f"{source('synthetic', 'stiffness_nm_per_rad')}: key 'synthetic.stiffness_nm_per_rad': no truth "
            f"for onset(s) {sorted(missing)} ms of study.perturbation_onsets_ms"
        )
    device = settings["device"].subject
    if device is not None and device not in study.rows:
        raise LoperInputError(
            f"{source('device', 'subject')}: key 'device.subject': subject '{device}' is not in {sheet}"
        )


def raw_file_warnings(study: Study, sheet: str | None = None) -> list[str]:
    """Check every recorded subject's raw folder: a path that is not a readable file, a file named in
    another case, or two robot logs of one trial (its ``.loper.tsv`` and ``.mat``) stops the run (never a trial
    silently left out, nor one of two logs silently read); returns a warning per folder naming the
    files that match no trial of the design. Given the subject sheet's name ``sheet``, the raw folders'
    recordings are checked first (:func:`check_recordings`).

    Raises
    ------
    LoperInputError
        Naming the file.
    """
    if sheet is not None:
        check_recordings(study, sheet)
    said, trials, design = [], study.design.trials(), study.design
    for s in (s for s, row in study.rows.items() if row["source"] == "recorded"):
        raw = study.paths.raw_folder(s)
        for trial in trials:
            present = [
                raw / f"{trial}{suffix}"
                for suffix in RAW_SUFFIXES
                if raw_file_present(raw / f"{trial}{suffix}", f"raw file of trial '{trial}' of subject '{s}'")
            ]
            logs = [p for p in present if p.name != f"{trial}.c3d"]
            if len(logs) > 1:  # a .loper.tsv and a .mat: the trial's robot log would be one of them, unsaid
                raise LoperInputError(
                    f"{' and '.join(map(str, logs))}: two robot logs of trial '{trial}' of subject '{s}'; a trial "
                    "has one (its .loper.tsv or the robot's .mat export): keep one and move the other out of "
                    f"{raw}"
                )
        refuse_miscased_raw_files(raw, trials)
        unmatched = unmatched_raw_files(raw, trials)
        if unmatched:
            said.append(
                f"warning: {raw}: {', '.join(unmatched)}: no trial of the design has this name, not analysed "
                f"(trials: {', '.join(trials)}; from study.static, study.no_device, study.device, "
                f"study.perturbation_onsets_ms {list(design.perturbation_onsets_ms)} and study.perturbation_repeats "
                f"{design.perturbation_repeats})"
            )
    return said


def refuse_recordings_in_synthetic_folders(study: Study, sheet: str) -> None:
    """A synthetic subject's raw folder holds only raw files the workflow generated (vouched for by their manifests,
    :mod:`loper_analysis.io.generated`): the synthetic lab would write over any other, a recording.

    ``sheet``: the subject sheet's name.

    Raises
    ------
    LoperInputError
        Naming the sheet, the subject's row, the folder, the files and what to do.
    """
    for s in (s for s, row in study.rows.items() if row["source"] == "synthetic"):
        raw = study.paths.raw_folder(s)
        foreign = unvouched_files(raw)
        if not foreign:
            continue
        manifests = sorted(p.name for p in raw.glob(f"*{MANIFEST_SUFFIX}"))
        names = ", ".join(f"{name} ({why})" for name, why in foreign)
        earlier = (
            ""
            if manifests
            else f" (no manifest *{MANIFEST_SUFFIX} in the folder: files the synthetic lab wrote before it kept one "
            "are not told from recordings either; delete those and they are generated again)"
        )
        raise LoperInputError(
            f"{sheet}: subject '{s}', column source: 'synthetic', but its raw folder {raw} holds raw files the "
            f"workflow did not generate: {names}; the synthetic lab would write over them. If they are the "
            f"subject's recordings, mark the row 'recorded'; if the subject is to be simulated, move these files "
            f"out of {raw}{earlier}"
        )


def refuse_repeated_recordings(study: Study) -> None:
    """Every trial of the recorded subjects has its own recording: no raw file is another trial's (of the same
    subject or of another), by link or by copy (:func:`loper_analysis.io.raw_files.repeated_files`); the fit would
    pool the same strides twice and report too narrow an interval.

    Raises
    ------
    LoperInputError
        Naming both files of every such pair, and how they are the same.
    """
    trials = study.design.trials()
    paths = [
        study.paths.raw_folder(s) / f"{trial}{suffix}"
        for s, row in study.rows.items()
        if row["source"] == "recorded"
        for trial in trials
        for suffix in RAW_SUFFIXES
    ]
    repeats = repeated_files(paths)
    if repeats:
        lines = [f"{repeat} is the same recording as {first} ({how})" for repeat, first, how in repeats]
        raise LoperInputError(
            "; ".join(lines) + ": one recording stands for one trial (the fit would pool its strides twice); put "
            "each trial's own recording in its place, or remove the repeated file"
        )


def check_recordings(study: Study, sheet: str) -> None:
    """No recording written over by the synthetic lab (:func:`refuse_recordings_in_synthetic_folders`), none
    standing for two trials (:func:`refuse_repeated_recordings`).

    Raises
    ------
    LoperInputError
        From either check.
    """
    refuse_recordings_in_synthetic_folders(study, sheet)
    refuse_repeated_recordings(study)
