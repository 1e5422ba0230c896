# Shared set-up: config and subject-sheet validation, target list, settings for rules.
import re
import sys
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from snakemake.common.configfile import load_configfile

from loper_analysis.cluster import check_slurm_submission
from loper_analysis.config_file import config_layers
from loper_analysis.config_sections import translated
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_parameter_section import force_platforms_used
from loper_analysis.io.readers import read_subject_sheet
from loper_analysis.layout import Study, fill, subject_rows
from loper_analysis.schema import check_config, check_project_paths, config_origin
from loper_analysis.stages.cluster_failures import requested_partitions
from loper_analysis.study_checks import check_subject_sheet, check_subjects, raw_file_warnings
from loper_analysis.stages.settings import stage_settings
from loper_analysis.study_design import DEVICE_TESTS
from loper_analysis.stages import STAGES, study_paths

_SCHEMAS = Path(workflow.basedir) / "workflow" / "schemas"


# Where each value came from, highest priority first: --config, the --configfile files last to first, the default.
CONFIG_LAYERS = config_layers(workflow.config_settings.config, workflow.config_settings.configfiles, load_configfile)


def config_source(*key_path) -> str:
    """The file or command-line option that set a config key (config/config.yaml unless overridden)."""
    return config_origin(key_path, CONFIG_LAYERS, "config/config.yaml")


# a config file of the former layout (trials, filter, opensim, identification): each key read at its place now, said once
_moved = translated(config)
if _moved:
    print(f"config: keys of the former layout read at their places now: {'; '.join(_moved)}", file=sys.stderr)

try:
    # one short message naming the file or option, the key and the value; then Snakemake's own validation
    check_config(config, _SCHEMAS / "config.schema.yaml", "config/config.yaml", CONFIG_LAYERS)
    validate(config, "../schemas/config.schema.yaml")
    check_project_paths(config, Path.cwd(), lambda key_path: config_source(*key_path))  # allow_outside_project
    #: every stage's settings, each built by its stage's reader (loper_analysis.stages.settings)
    SETTINGS = {name: stage_settings(config, name) for name in ("study", *(stage.name for stage in STAGES))}
    _subjects_path = Path(SETTINGS["study"].subjects)
    if not _subjects_path.is_file():
        raise LoperInputError(f"{config_source('subjects')}: key 'subjects': file '{_subjects_path}' not found")
    subjects = read_subject_sheet(_subjects_path)
    check_subject_sheet(subjects, _SCHEMAS / "subjects.schema.yaml", str(_subjects_path))  # IDs' length first
    validate(subjects, "../schemas/subjects.schema.yaml")
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None
if subjects["subject"].duplicated().any():
    dup = subjects.loc[subjects["subject"].duplicated(), "subject"].iloc[0]
    raise WorkflowError(f"{_subjects_path}: subject '{dup}' appears twice")


def _note(line: str) -> None:
    print(line, file=sys.stderr)


def _plates(path) -> bool:
    """Whether a recorded trial's C3D has force platforms (its GRF as OpenSim external loads is made)."""
    try:
        return force_platforms_used(path)
    except LoperInputError as exc:
        raise WorkflowError(str(exc)) from None


#: Every file's path (loper_analysis.layout): PATHS the patterns, STUDY the subjects' trials, bundles and targets.
PATHS = study_paths(SETTINGS["study"].raw_dir)
try:
    #: subject -> its sheet row (a synthetic subject's missing anthropometrics drawn from the study's subjects)
    SUBJECT_ROWS = subject_rows(subjects, SETTINGS["study"].seed)
    SUBJECT_SOURCE = {s: row["source"] for s, row in SUBJECT_ROWS.items()}
    STUDY = Study(SUBJECT_ROWS, SETTINGS, PATHS, _plates, _note)
    DESIGN = STUDY.design
    check_subjects(STUDY, str(_subjects_path), config_source)
    for _line in raw_file_warnings(STUDY, str(_subjects_path)):  # and check_recordings
        _note(_line)
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None
_synthetic = [s for s, src in SUBJECT_SOURCE.items() if src == "synthetic"]
SYNTHETIC_PATTERN = "|".join(_synthetic) if _synthetic else "(?!)"
VALIDATION_CHUNKS = [f"{i:03d}" for i in range(SETTINGS["validation"].n_chunks)]


wildcard_constraints:
    subject=r"[A-Za-z0-9-]+",
    chunk=r"[0-9]{3}",
    onset=r"[0-9]{3}",
    trial=r"[A-Za-z0-9-]+",


onstart:
    # a SLURM run: check sbatch and the partitions before the first submission (loper_analysis.cluster)
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        try:
            check_slurm_submission(requested_partitions(workflow.resource_settings))
        except LoperInputError as exc:
            raise WorkflowError(str(exc)) from None


onsuccess:
    # what the run found wrong, on the console (each also in its job's log and in its table)
    from loper_analysis.stages.report.step import run_warnings

    _said = run_warnings(
        PATHS.strides.summary, [fill(PATHS.model.scale, subject=s) for s in STUDY.scaled_subjects()]
    )
    if _said:
        print("warnings of this run's results:", *(f"  {line}" for line in _said), sep="\n", file=sys.stderr)


onerror:
    # a SLURM run: say which failed jobs SLURM itself ended, and why (memory, time limit, cancel)
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        from loper_analysis.stages.cluster_failures import slurm_failure_lines

        for _path in [log] if isinstance(log, (str, Path)) else log:  # Snakemake 9 passes a list of logs
            for _line in slurm_failure_lines(_path):
                print(_line, file=sys.stderr)
