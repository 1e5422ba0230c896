"""The transparency stage's files: its result files (name -> pattern under ``results/transparency/``) and the
stride and cycle tables of each subject's pair of trials."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING

from loper_analysis.io.atomic import PathLike
from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = ["FILES", "report_tables", "TransparencyFiles", "transparency_files", "targets"]

FILES: dict[str, str] = {
    "rmsd": "rmsd.tsv",
    "force": "force.tsv",
    "figure": "transparency.png",
}


@dataclass(frozen=True)
class TransparencyFiles:
    """One subject's stride and cycle tables (TSV) of walking without and with the device."""

    no_device_strides: PathLike
    no_device_cycles: PathLike
    device_strides: PathLike
    device_cycles: PathLike


def transparency_files(study: Study) -> dict:
    """Stride and cycle tables of the transparency pair of every subject that walked both trials (subject ->
    ``TransparencyFiles``)."""
    st, d = study.paths.strides, study.design
    return {
        s: TransparencyFiles(
            no_device_strides=fill(st.strides, subject=s, trial=d.no_device),
            no_device_cycles=fill(st.cycles, subject=s, trial=d.no_device),
            device_strides=fill(st.strides, subject=s, trial=d.device),
            device_cycles=fill(st.cycles, subject=s, trial=d.device),
        )
        for s in study.transparency_subjects()
    }


def targets(study: Study) -> list[str]:
    """The transparency tables and figure, with a subject who walked both trials of the pair."""
    t = study.paths.transparency
    return [t.rmsd, t.force, t.figure] if study.transparency_subjects() else []


def transparency_inputs(study: Study) -> list[str]:
    """Every table of the transparency pairs (:func:`transparency_files`)."""
    return [path for files in transparency_files(study).values() for path in dataclasses.astuple(files)]


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: the transparency's, with a subject who walked both trials."""
    if not study.transparency_subjects():
        return {}
    t = study.paths.transparency
    return {"Transparency: RMSD vs ISV_ave": t.rmsd, "Transparency: interaction force": t.force}
