"""The planning stage's files: its result files (name -> pattern under ``results/planning/``) and the pilot's files
the planner reads."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from loper_analysis.io.atomic import PathLike
from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "PilotFiles", "PilotTrial", "planning_files", "targets"]

FILES: dict[str, str] = {
    "plan": "plan.tsv",
    "answers": "answers.txt",
}


@dataclass(frozen=True)
class PilotTrial:
    """A pilot trial walked with the device: its joint-angle and stride tables (TSV)."""

    angles: PathLike
    strides: PathLike


@dataclass(frozen=True)
class PilotFiles:
    """The pilot's files the planner reads.

    ``trials``: the pilot's trials walked with the device (name -> :class:`PilotTrial`): their unperturbed
    strides are the null pairs; the perturbed strides of the trials at an onset are its perturbed pairs
    (:func:`loper_analysis.planning.inputs.pilot_perturbed_pairs`), whose scatter the prediction takes
    (the null pairs' when there are none, with a note in the rows). ``segments``: the segment table of the
    subject to plan for (the pilot's, or another subject's). ``impedance``: impedance rows
    (``results/impedance/{subject}/{onset}.tsv`` or ``results/impedance/impedance.tsv``) whose pilot estimates
    are the planned impedance (none: the values are given to :func:`plan`).
    """

    trials: Mapping[str, PilotTrial]
    segments: PathLike
    impedance: tuple[PathLike, ...] = ()


def planning_files(study: Study, pilot: str):
    """The pilot's angle and stride tables of its trials with the device, its segment table and fit rows
    (``PilotFiles``)."""
    p = study.paths
    return PilotFiles(
        trials={
            t: PilotTrial(
                angles=fill(p.ik.angles, subject=pilot, trial=t),
                strides=fill(p.strides.strides, subject=pilot, trial=t),
            )
            for t in study.null_pair_trials(pilot)
        },
        segments=fill(p.model.segments, subject=pilot),
        impedance=tuple(study.onset_files("impedance", "fit", pilot)),
    )


def targets(study: Study) -> list[str]:
    """With perturbation trials: the plan and its answers."""
    p = study.paths.planning
    return [p.plan, p.answers] if study.identifies_impedance() else []


def planning_inputs(study: Study, pilot: str) -> list[str]:
    """Every file the planner reads for the pilot (:func:`planning_files`)."""
    files = planning_files(study, pilot)
    tables = [path for trial in files.trials.values() for path in (trial.angles, trial.strides)]
    return [*tables, files.segments, *files.impedance]
