"""The dynamics stage's files: its result files (name -> pattern under ``results/dynamics/``), the files one
trial's inverse dynamics reads, the trials it runs for and those it cannot, and its targets."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike
from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = [
    "FILES",
    "report_tables",
    "NO_PLATES",
    "DynamicsFiles",
    "dynamics_files",
    "dynamics_trials",
    "targets",
    "trials_without",
]

FILES: dict[str, str] = {
    "moments": "{subject}/{trial}.moments.tsv",
    "cycles": "{subject}/{trial}.cycles.tsv",
    "summary": "{subject}/{trial}.summary.tsv",
    "figure": "{subject}/{trial}.moments.png",
    "trials": "trials.tsv",
}

#: Why a trial without force platforms gets no inverse dynamics.
NO_PLATES = (
    "no force platforms in the C3D (FORCE_PLATFORM:USED 0 or absent): the belts' vertical forces carry no centre "
    "of pressure, horizontal force or free moment, which inverse dynamics needs"
)


@dataclass(frozen=True)
class DynamicsFiles:
    """The files one trial's inverse dynamics reads.

    Attributes
    ----------
    model_osim : path-like
        The subject's scaled OpenSim model (``results/model/{subject}/scaled.osim``); its total mass is the body mass.
    ik_mot : path-like
        The IK coordinates (``.mot``; degrees when ``inDegrees=yes``).
    grf_mot : path-like
        The ground reactions (``grf`` step's ``.grf.mot``, model frame, with each plate's COP columns).
    contacts_tsv, events_tsv, strides_tsv : path-like
        The ``events`` step's contacts and events, the ``strides`` step's stride table.
    """

    model_osim: PathLike
    ik_mot: PathLike
    grf_mot: PathLike
    contacts_tsv: PathLike
    events_tsv: PathLike
    strides_tsv: PathLike


def dynamics_trials(study: Study) -> list[tuple[str, str]]:
    """(subject, trial) of every recorded subject's walking trial with force platforms."""
    return [
        (s, t)
        for s in study.processed_subjects()
        if study.source(s) == "recorded"
        for t in study.subject_trials(s)
        if study.has_force_platforms(s, t)
    ]


def trials_without(study: Study) -> list[tuple[str, str, str]]:
    """(subject, trial, reason) of every processed walking trial that gets no inverse dynamics."""
    done = set(dynamics_trials(study))
    return [
        (s, t, NO_PLATES) for s in study.processed_subjects() for t in study.subject_trials(s) if (s, t) not in done
    ]


def dynamics_files(study: Study, subject: str, trial: str) -> DynamicsFiles:
    """The files of one trial's inverse dynamics: the subject's model, the trial's IK, ground reactions, contacts,
    events and strides.

    Raises
    ------
    LoperInputError
        A trial that gets no inverse dynamics (a synthetic subject's, or one without force platforms), naming it
        and why.
    """
    if (subject, trial) not in dynamics_trials(study):
        why = (
            NO_PLATES
            if study.source(subject) == "recorded"
            else ("a synthetic subject's trials hold the belts' vertical forces only (no centre of pressure)")
        )
        raise LoperInputError(
            f"{subject}/{trial}: no inverse dynamics: {why}; {study.paths.dynamics.trials} says which trials have it"
        )
    p, s, t = study.paths, subject, trial
    return DynamicsFiles(
        model_osim=study.subject_model(s),
        ik_mot=fill(p.ik.mot, subject=s, trial=t),
        grf_mot=fill(p.grf.mot, subject=s, trial=t),
        contacts_tsv=fill(p.events.contacts, subject=s, trial=t),
        events_tsv=fill(p.events.events, subject=s, trial=t),
        strides_tsv=fill(p.strides.strides, subject=s, trial=t),
    )


def targets(study: Study) -> list[str]:
    """Every trial's moments, cycles and figure where it has force platforms, and the table of every processed
    trial saying whether it got inverse dynamics and why not."""
    d = study.paths.dynamics
    out = [fill(getattr(d, f), subject=s, trial=t) for s, t in dynamics_trials(study) for f in ("cycles", "figure")]
    return [*out, d.trials] if study.processed_subjects() else out


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: every trial's inverse dynamics or why not."""
    return {"Inverse dynamics per trial": study.paths.dynamics.trials}
