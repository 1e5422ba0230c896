"""The impedance stage's files: its result files (name -> pattern under ``results/impedance/``) and the bundle of
files a subject's fits read and write."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from loper_analysis.errors import LoperInputError
from loper_analysis.io.atomic import PathLike
from loper_analysis.layout import fill

if TYPE_CHECKING:
    from loper_analysis.layout import Study

__all__ = [
    "FILES",
    "report_tables",
    "FitFiles",
    "FitOutputs",
    "TrialFiles",
    "fit_files",
    "fit_inputs",
    "fits_couplings",
    "targets",
]

FILES: dict[str, str] = {
    "response": "{subject}/{onset}.response.tsv",
    "counts": "{subject}/{onset}.counts.tsv",
    "fit": "{subject}/{onset}.tsv",
    "curves": "{subject}/{onset}.curves.tsv",
    "force": "{subject}/{onset}.force.tsv",
    "couplings": "{subject}/{onset}.couplings.tsv",
    "responses_figure": "{subject}/responses.png",
    "fit_figure": "{subject}/fit.png",
    "table": "impedance.tsv",
    "coupling_table": "couplings.tsv",
    "summary": "summary.tsv",
    "literature": "literature.tsv",
    "figure": "impedance.png",
}


@dataclass(frozen=True)
class TrialFiles:
    """The files of one trial a fit reads.

    ``angles`` and ``strides``: its joint-angle and stride tables (TSV), for every trial. A trial of the
    onset itself also gives ``force`` (the load cell on the marker frames, TSV) and ``markers`` (TRC, for
    the brace markers), and optionally ``force_native`` (the load cell at the robot rate,
    ``{trial}.force_native.tsv``, from which the fit then takes its force).
    """

    angles: PathLike
    strides: PathLike
    force: PathLike | None = None
    markers: PathLike | None = None
    force_native: PathLike | None = None


@dataclass(frozen=True)
class FitOutputs:
    """The files one fit writes (TSV): the mean ``response``, the stride ``counts``, the ``fit`` rows, the fit
    ``curves`` and, optionally, the mean ``force`` the model saw and the inter-joint ``couplings``' rows (a fit with
    ``impedance.couplings``)."""

    response: PathLike
    counts: PathLike
    fit: PathLike
    curves: PathLike
    force: PathLike | None = None
    couplings: PathLike | None = None


@dataclass(frozen=True)
class FitFiles:
    """The files of one subject's fit at one onset.

    ``trials``: the onset's own trials (name -> :class:`TrialFiles` with ``force`` and ``markers``), in the
    order the fit takes them; ``null_trials``: the trials whose unperturbed strides are the null pairs
    (their ``angles`` and ``strides`` are read); ``segments``: the segment table (read when the onset has a
    trial); ``outputs``: what the fit writes; ``truth``: a synthetic subject's ``truth.yaml`` (None: recorded).

    Raises
    ------
    LoperInputError
        An own trial without its force or markers file (naming the trial).
    """

    trials: Mapping[str, TrialFiles]
    segments: PathLike
    outputs: FitOutputs
    null_trials: Mapping[str, TrialFiles] = field(default_factory=dict)
    truth: PathLike | None = None

    def __post_init__(self):
        for name, files in self.trials.items():
            if files.force is None or files.markers is None:
                raise LoperInputError(f"fit files: trial {name} of the onset needs its force and markers files")


def fit_files(study: Study, subject: str) -> dict:
    """Files of a subject's fit at every onset (ms -> ``FitFiles``, the config's order): the onset's own
    trials (angles, strides, force at 128 Hz and at the robot rate, markers), the null-pair trials (angles,
    strides), the segment table, a synthetic truth and the outputs."""
    s, p = subject, study.paths

    def trial_files(t: str, own: bool) -> TrialFiles:
        tables = dict(angles=fill(p.ik.angles, subject=s, trial=t), strides=fill(p.strides.strides, subject=s, trial=t))
        if own:
            tables.update(
                force=fill(p.events.force, subject=s, trial=t),
                markers=fill(p.markers.trc, subject=s, trial=t),
                force_native=fill(p.events.force_native, subject=s, trial=t),
            )
        return TrialFiles(**tables)

    def null_trials(onset: int) -> list[str]:
        # none for a white-noise fit or a missing onset (reported without any input)
        if study.settings["impedance"].identification.noise_model != "null_pairs" or not study.onset_trials(s, onset):
            return []
        return study.null_pair_trials(s)

    outputs = ("response", "counts", "fit", "curves", "force") + (("couplings",) if fits_couplings(study) else ())
    return {
        o: FitFiles(
            trials={t: trial_files(t, True) for t in study.onset_trials(s, o)},
            segments=fill(p.model.segments, subject=s),
            outputs=FitOutputs(**{k: fill(getattr(p.impedance, k), subject=s, onset=o) for k in outputs}),
            null_trials={t: trial_files(t, False) for t in null_trials(o)},
            truth=fill(p.raw.truth, subject=s) if study.source(s) == "synthetic" else None,
        )
        for o in study.design.perturbation_onsets_ms
    }


def fits_couplings(study: Study) -> bool:
    """Whether the fits add inter-joint couplings (``impedance.couplings``), and so write their tables."""
    return bool(study.settings["impedance"].identification.couplings)


def fit_inputs(study: Study, subject: str) -> list[str]:
    """Every file a subject's fits read (:meth:`fit_files`), each once."""
    paths = []
    for files in fit_files(study, subject).values():
        paths += [files.segments, *([files.truth] if files.truth else [])]
        for trial in (*files.trials.values(), *files.null_trials.values()):
            paths += [path for path in vars(trial).values() if path is not None]
    return list(dict.fromkeys(paths))


def targets(study: Study) -> list[str]:
    """With perturbation trials: the impedance tables, their figure and every processed subject's figures."""
    if not study.identifies_impedance():
        return []
    p = study.paths.impedance
    figures = ("responses_figure", "fit_figure")
    subjects = [fill(getattr(p, f), subject=s) for s in study.processed_subjects() for f in figures]
    couplings = [p.coupling_table] if fits_couplings(study) else []
    return [p.table, p.summary, p.literature, p.figure, *couplings, *subjects]


def report_tables(study: Study) -> dict[str, str]:
    """Heading -> table of the run's Markdown tables: the impedance per subject, its summary, the literature and,
    with ``impedance.couplings``, the inter-joint couplings per subject and onset."""
    p = study.paths.impedance
    tables = {
        "Impedance per subject, onset and joint": p.table,
        "Across-subject summary": p.summary,
        "Literature": p.literature,
    }
    if fits_couplings(study):
        tables["Inter-joint couplings per subject and onset"] = p.coupling_table
    return tables
