"""The pipeline's stages, one slice each, and the file layer they share.

:data:`STAGES` lists every stage in the order of the workflow's graph (a
stage reads only the results of stages before it). Each slice
``loper_analysis.stages.<name>`` holds the stage's file step (``step``: reads
its input files, calls the library, which works on arrays and tables only,
and writes exactly its declared outputs through the atomic writer,
:mod:`loper_analysis.io.atomic`) and its result files (``files``). The
workflow's rule includes, the results folders (:data:`RESULT_FILES`, :func:`study_paths`)
and the layout's tests are built from this list.

Shared by every stage: :func:`rule_log` (a rule's script runs its step inside
it: messages, warnings and, on failure, the full error go to the job's log);
besides the stages, :mod:`.inspect` (the ``inspect`` command's file step) and
:mod:`.cluster_failures` (why SLURM ended the failed jobs of a run).
"""

from loper_analysis.layout import RAW_DIR, RESULTS_DIR, Paths, Study
from loper_analysis.stages import (
    device,
    dynamics,
    events,
    grf,
    ik,
    impedance,
    markers,
    model,
    planning,
    report,
    strides,
    synthetic,
    transparency,
    validation,
)
from loper_analysis.stages.logs import rule_log
from loper_analysis.stages.stage import Stage

#: Every stage, in the order of the workflow's graph.
STAGES: tuple[Stage, ...] = (
    synthetic.STAGE,
    markers.STAGE,
    model.STAGE,
    ik.STAGE,
    grf.STAGE,
    events.STAGE,
    strides.STAGE,
    dynamics.STAGE,
    transparency.STAGE,
    device.STAGE,
    impedance.STAGE,
    planning.STAGE,
    validation.STAGE,
    report.STAGE,
)

#: Every result file: stage folder -> name -> pattern under ``results/{stage}/``, from the stages' files.
RESULT_FILES: dict[str, dict[str, str]] = {stage.name: dict(stage.files) for stage in STAGES if stage.files}


def study_paths(raw_dir: str = RAW_DIR, results_dir: str = RESULTS_DIR) -> Paths:
    """Every file pattern of a study (:class:`~loper_analysis.layout.Paths`) with the stages' result files:
    ``study_paths().ik.angles`` is ``results/ik/{subject}/{trial}.angles.tsv``."""
    return Paths(RESULT_FILES, raw_dir, results_dir)


def all_targets(study: Study) -> list[str]:
    """Everything a run builds by default: every stage's targets (its files' ``targets``), in the stages'
    order."""
    return [path for stage in STAGES if stage.targets is not None for path in stage.targets(study)]


def report_tables(study: Study) -> dict[str, str]:
    """The tables of the run's Markdown rendering (``results/report/tables.md``): heading -> table, every stage's
    ``tables`` in the stages' order."""
    return {
        heading: path for stage in STAGES if stage.tables is not None for heading, path in stage.tables(study).items()
    }


__all__ = ["RESULT_FILES", "STAGES", "Stage", "all_targets", "report_tables", "rule_log", "study_paths"]
