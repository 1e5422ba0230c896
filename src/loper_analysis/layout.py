"""Where every file of a study lives: the raw files, the results, the rules' logs and benchmarks, the files each
job reads and the targets of a run.

This module is the only place that spells a path. :class:`Paths` holds the
file patterns (Snakemake wildcards in braces: ``{subject}``, ``{trial}``,
``{onset}``, ``{chunk}``), one attribute per stage folder::

    paths = Paths(raw_dir="data/raw")
    paths.ik.angles            # 'results/ik/{subject}/{trial}.angles.tsv'
    paths.raw.c3d              # 'data/raw/{subject}/{trial}.c3d'
    fill(paths.ik.angles, subject="S01", trial="pert050-1")

:class:`Study` adds the subjects and the trial design: which trials of which
subject exist, the bundles of files a job reads and the targets of a run.
The workflow's rules, the command line and the benchmarks ask these two.
"""

from __future__ import annotations

import string
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from loper_analysis.errors import LoperInputError
from loper_analysis.study_design import StudyDesign

__all__ = ["RAW_DIR", "RESULTS_DIR", "RAW_FILES", "Paths", "Study", "fill", "subject_rows"]

#: The raw files' folder unless the config's ``raw_dir`` says otherwise.
RAW_DIR = "data/raw"
#: The results' folder.
RESULTS_DIR = "results"

#: The raw files of a subject: name -> pattern under the raw folder.
RAW_FILES: dict[str, str] = {
    "c3d": "{subject}/{trial}.c3d",
    "robot_log": "{subject}/{trial}.loper.tsv",
    "mat": "{subject}/{trial}.mat",
    "truth": "{subject}/truth.yaml",
}


def subject_rows(sheet: pd.DataFrame, seed: int) -> dict[str, dict]:
    """Subject -> its row of the subject sheet, empty cells left out; a synthetic subject's missing
    anthropometrics drawn from the study's subjects (``synthetic.subjects.subject_anthropometry``)."""
    from loper_analysis.synthetic.subjects import subject_anthropometry

    rows = {
        r["subject"]: {k: v for k, v in r.items() if not (isinstance(v, float) and pd.isna(v))}
        for r in sheet.to_dict("records")
    }
    for row in rows.values():
        if row["source"] == "synthetic":
            row.update(subject_anthropometry(row, seed))
    return rows


class _Keep(dict):
    """Format fields: the given ones filled, the others kept as wildcards."""

    def __missing__(self, key: str) -> str:
        return "{" + key + "}"


def fill(pattern: str, **fields) -> str:
    """``pattern`` with the given wildcards filled and the others left as they are (``{onset}`` of an int is
    written with three digits)."""
    values = {k: f"{v:03d}" if k == "onset" and isinstance(v, int) else str(v) for k, v in fields.items()}
    return string.Formatter().vformat(pattern, (), _Keep(values))


class Folder:
    """The file patterns of one folder, as attributes (``Folder.angles``)."""

    def __init__(self, root: str, files: Mapping[str, str]):
        self.root = root
        self._files = {name: f"{root}/{pattern}" for name, pattern in files.items()}

    def __getattr__(self, name: str) -> str:
        try:
            return self.__dict__["_files"][name]
        except KeyError:
            raise AttributeError(f"{self.root}: no file '{name}' (files: {', '.join(self._files)})") from None

    def __dir__(self):
        return [*super().__dir__(), *self._files]


class Paths:
    """Every file pattern of a study: ``raw`` (the raw folder, the config's ``raw_dir``) and one attribute per
    results folder (``result_files``: folder -> name -> pattern, the stages' files,
    :data:`loper_analysis.stages.RESULT_FILES`), plus the rules' logs and benchmarks."""

    def __init__(
        self, result_files: Mapping[str, Mapping[str, str]], raw_dir: str = RAW_DIR, results_dir: str = RESULTS_DIR
    ):
        self.raw_dir, self.results_dir = str(raw_dir).rstrip("/"), str(results_dir).rstrip("/")
        self.raw = Folder(self.raw_dir, RAW_FILES)
        self._folders = tuple(result_files)
        for stage, files in result_files.items():
            setattr(self, stage, Folder(f"{self.results_dir}/{stage}", files))

    def log(self, rule: str, key: str) -> str:
        """A rule's log: ``results/logs/{rule}/{key}.log`` (``key``: its wildcards, e.g. ``{subject}/{trial}``)."""
        return f"{self.results_dir}/logs/{rule}/{key}.log"

    def benchmark(self, rule: str, key: str) -> str:
        """A rule's benchmark table: ``results/benchmarks/{rule}/{key}.tsv``."""
        return f"{self.results_dir}/benchmarks/{rule}/{key}.tsv"

    def raw_folder(self, subject: str) -> Path:
        """A subject's raw folder."""
        return Path(self.raw_dir) / subject

    def __getattr__(self, name: str) -> Folder:  # for type checkers: the stage folders are set in __init__
        raise AttributeError(f"no results folder '{name}' (folders: {', '.join(self.__dict__.get('_folders', ()))})")


@dataclass
class Study:
    """The study's subjects and trials on disk, the files each job reads and the run's targets.

    Parameters
    ----------
    rows : mapping
        Subject -> its subject-sheet row (``source``, optional ``model_osim``, ``mass_kg``, ``height_m``).
    settings : mapping
        Stage name -> its settings, as its reader builds them (:func:`loper_analysis.stages.settings.stage_settings`;
        ``"study"``: the study's). Read here: the study's design and subject sheet, the device tests' subject,
        the generic model, the markers' label maps, the planner's pilot and the events' belt channels.
    paths : Paths
        The file patterns.
    has_plates : callable
        ``has_plates(path) -> bool``: whether a C3D has force platforms (read once per file).
    note : callable
        Where notes for the user go (one line each).
    """

    rows: Mapping[str, Mapping]
    settings: Mapping[str, Any]
    paths: Paths
    has_plates: Callable[[Path], bool]
    note: Callable[[str], None] = print
    _plates: dict = field(default_factory=dict, repr=False)

    @property
    def design(self) -> StudyDesign:
        """The trial design (the study's settings)."""
        return self.settings["study"].design

    # --- subjects and trials -------------------------------------------------------------------------------
    def source(self, subject: str) -> str:
        """``synthetic`` or ``recorded``."""
        return self.rows[subject]["source"]

    def subject_trials(self, subject: str) -> list[str]:
        """Walking trials of a subject: all for a synthetic one, those with a raw C3D on disk for a recorded one."""
        if self.source(subject) == "synthetic":
            return self.design.walking_trials()
        raw = self.paths.raw_folder(subject)
        return [t for t in self.design.walking_trials() if (raw / f"{t}.c3d").is_file()]

    def processed_subjects(self) -> list[str]:
        """Synthetic subjects, and recorded subjects with a static trial on disk or a scaled model."""
        static = self.design.static
        return [
            s
            for s, row in self.rows.items()
            if row["source"] == "synthetic"
            or "model_osim" in row
            or (self.paths.raw_folder(s) / f"{static}.c3d").is_file()
        ]

    def scaled_subjects(self) -> list[str]:
        """Processed subjects whose model is scaled here from their static trial (no model_osim)."""
        return [s for s in self.processed_subjects() if "model_osim" not in self.rows[s]]

    def transparency_subjects(self) -> list[str]:
        """Processed subjects with both walking trials of the transparency experiment."""
        pair = {self.design.no_device, self.design.device}
        return [s for s in self.processed_subjects() if pair <= set(self.subject_trials(s))]

    def onset_trials(self, subject: str, onset: int | str) -> list[str]:
        """The subject's trials of one onset (ms) that are on disk (or generated)."""
        return [t for t in self.subject_trials(subject) if self.design.onset_ms(t) == int(onset)]

    def null_pair_trials(self, subject: str) -> list[str]:
        """The subject's trials with the device: their unperturbed strides are the null pairs of every fit."""
        return [t for t in self.subject_trials(subject) if t != self.design.no_device]

    def has_force_platforms(self, subject: str, trial: str) -> bool:
        """Whether a recorded trial's C3D has force platforms; a file without them gets one note."""
        key = (subject, trial)
        if key not in self._plates:
            path = Path(fill(self.paths.raw.c3d, subject=subject, trial=trial))
            self._plates[key] = self.has_plates(path)
            if not self._plates[key]:
                self.note(
                    f"note: {path}: no force platforms (FORCE_PLATFORM:USED 0 or absent): events from the belt "
                    f"channels (events.grf_channels: {self.settings['events'].events.grf_channels}), no OpenSim "
                    f"external loads ({fill(self.paths.grf.mot, subject=subject, trial=trial)}) for this trial"
                )
        return self._plates[key]

    # --- files of one job ------------------------------------------------------------------------------------
    def subject_model(self, subject: str) -> str:
        """The subject's OpenSim model: the sheet's model_osim or the one scaled from the static trial."""
        return self.rows[subject].get("model_osim") or fill(self.paths.model.scaled, subject=subject)

    def generic_model(self, subject: str) -> str:
        """The model scaled per subject: model.generic_model, or the generated model for the subject."""
        return self.settings["model"].generic_model or fill(self.paths.model.generic, subject=subject)

    def static_markers(self, subject: str) -> list[str]:
        """The static trial's TRC of a subject with a static trial (generated for a synthetic subject, on disk for a
        recorded one): IK compares each walking trial's marker geometry with it. Nothing for a subject with only a
        model (the sheet's model_osim): IK compares with the model's markers."""
        static = self.design.static
        if self.source(subject) == "synthetic" or (self.paths.raw_folder(subject) / f"{static}.c3d").is_file():
            return [fill(self.paths.markers.trc, subject=subject, trial=static)]
        return []

    def static_c3d_for_mass(self, subject: str) -> list[str]:
        """The static trial's C3D when the sheet gives no mass or no height (read for them), else nothing."""
        row = self.rows[subject]
        if "mass_kg" in row and "height_m" in row:
            return []
        return [fill(self.paths.raw.c3d, subject=subject, trial=self.design.static)]

    def static_c3d_for_scaling(self, subject: str) -> list[str]:
        """The static trial's C3D, read for the lab's stored widths (and the mass and height the sheet lacks)."""
        return [fill(self.paths.raw.c3d, subject=subject, trial=self.design.static)]

    def robot_log(self, subject: str, trial: str) -> str:
        """A trial's robot log: the raw ``{trial}.loper.tsv``, or converted from a recorded ``{trial}.mat``."""
        raw = fill(self.paths.raw.robot_log, subject=subject, trial=trial)
        mat = fill(self.paths.raw.mat, subject=subject, trial=trial)
        if self.source(subject) == "recorded" and not Path(raw).exists() and Path(mat).exists():
            return fill(self.paths.device.robot_log, subject=subject, trial=trial)
        return raw

    def device_log(self, trial: str) -> str | list:
        """The robot log of a device test (none without a device subject)."""
        subject = self.settings["device"].subject
        if subject is None:
            return []
        mat = fill(self.paths.raw.mat, subject=subject, trial=trial)
        if self.source(subject) == "recorded" and Path(mat).exists():
            return fill(self.paths.device.robot_log, subject=subject, trial=trial)
        return fill(self.paths.raw.robot_log, subject=subject, trial=trial)

    def label_maps(self, trial: str) -> list:
        """The label maps of a trial, merged in this order: markers.label_map, then its kind's and its own from
        markers.trial_label_maps (each inline, a mapping, or a file, a path)."""
        return self.settings["markers"].label_maps(trial, self.design.kind(trial))

    def recorded_checksums(self, paths: list[str]) -> dict[str, str]:
        """Path -> content checksum of the raw files among ``paths`` of recorded subjects (generated raw files
        are the workflow's own outputs, rerun by it)."""
        from loper_analysis.io.raw_files import content_checksum

        out = {}
        for path in paths:
            try:
                subject = Path(path).relative_to(self.paths.raw_dir).parts[0]
            except (ValueError, IndexError):
                continue
            if self.rows.get(subject, {}).get("source") == "recorded" and Path(path).is_file():
                out[path] = content_checksum(path)
        return out

    def stride_force(self, subject: str, trial: str) -> str | list:
        """The interaction force of a trial walked with the device (none without it)."""
        if trial == self.design.no_device:
            return []
        return fill(self.paths.events.force, subject=subject, trial=trial)

    def trial_files(self, stage: str, name: str) -> list[str]:
        """One file of every processed subject's walking trials (e.g. ``("strides", "strides")``)."""
        pattern = getattr(getattr(self.paths, stage), name)
        return [fill(pattern, subject=s, trial=t) for s in self.processed_subjects() for t in self.subject_trials(s)]

    def onset_files(self, stage: str, name: str, subject: str | None = None) -> list[str]:
        """One file per onset of one subject (or of every processed subject)."""
        pattern = getattr(getattr(self.paths, stage), name)
        subjects = self.processed_subjects() if subject is None else [subject]
        return [fill(pattern, subject=s, onset=o) for s in subjects for o in self.design.perturbation_onsets_ms]

    def planning_pilot(self, source: str = "planning.pilot_subject", sheet: str | None = None) -> str:
        """The pilot subject: planning.pilot_subject, else the first processed subject. ``source``: the file or
        option that set the key; ``sheet``: the subject sheet's name (the study's by default)."""
        pilot = self.settings["planning"].pilot_subject
        if pilot is None:
            return self.processed_subjects()[0]
        if pilot not in self.processed_subjects():
            raise LoperInputError(
                f"{source}: key 'planning.pilot_subject': subject '{pilot}' is not a processed subject of "
                f"{sheet or self.settings['study'].subjects}"
            )
        return pilot

    # --- targets ---------------------------------------------------------------------------------------------
    def identifies_impedance(self) -> bool:
        """Whether a processed subject has a perturbation trial (impedance, planning and validation are built)."""
        s_t = [(s, t) for s in self.processed_subjects() for t in self.subject_trials(s)]
        return any(self.design.onset_ms(t) is not None for _, t in s_t)

    def has_validation(self) -> bool:
        """Whether the validation study is built: for a study with perturbation trials, or without subjects."""
        return not self.processed_subjects() or self.identifies_impedance()

    def has_device_tests(self) -> bool:
        """Whether the device tests are built: with a device subject (device.subject not null)."""
        return self.settings["device"].subject is not None
