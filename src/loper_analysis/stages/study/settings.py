"""The study's settings: the trial design (config ``study``), ``seed``, ``subjects`` and ``raw_dir``."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from loper_analysis.study_design import StudyDesign

__all__ = ["NEEDS", "StudySettings", "read_settings"]

NEEDS: tuple[str, ...] = ()


@dataclass(frozen=True)
class StudySettings:
    """``design`` (:class:`~loper_analysis.study_design.StudyDesign`), ``seed`` (every random number derives
    from it), ``subjects`` (the subject sheet's path) and ``raw_dir`` (the raw files' folder)."""

    design: StudyDesign
    seed: int
    subjects: str
    raw_dir: str


def read_settings(config: Mapping) -> StudySettings:
    """The study of a validated config (``study.*``, ``seed``, ``subjects``, ``raw_dir``)."""
    trials = config["study"]
    design = StudyDesign(
        static=str(trials["static"]),
        no_device=str(trials["no_device"]),
        device=str(trials["device"]),
        perturbation_onsets_ms=tuple(int(o) for o in trials["perturbation_onsets_ms"]),
        perturbation_repeats=int(trials["perturbation_repeats"]),
        perturbed_side=str(trials["perturbed_side"]),
    )
    return StudySettings(design=design, seed=config["seed"], subjects=config["subjects"], raw_dir=config["raw_dir"])
