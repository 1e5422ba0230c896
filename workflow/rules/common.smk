# Shared set-up: config and subject-sheet validation, target list, settings for rules.
import re
import sys
from functools import cache
from pathlib import Path

import pandas as pd
from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

from snakemake.common.configfile import load_configfile

from loper_analysis.cluster import check_slurm_submission
from loper_analysis.errors import LoperInputError
from loper_analysis.io.c3d_parameter_section import force_platforms_used
from loper_analysis.io.raw_files import (
    content_checksum,
    RAW_SUFFIXES,
    raw_file_present,
    refuse_miscased_raw_files,
    unmatched_raw_files,
)
from loper_analysis.io.readers import read_subject_sheet
from loper_analysis.schema import check_config, check_table, config_origin
from loper_analysis.study_design import DEVICE_TESTS, StudyDesign
from loper_analysis.identification.validation import validation_settings
from loper_analysis.synthetic.subjects import subject_anthropometry, true_impedance

_SCHEMAS = Path(workflow.basedir) / "workflow" / "schemas"


def _shown(path) -> str:
    """A config file's name as the user typed it: relative to the working directory when inside it."""
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return str(path)


# Where each value came from, highest priority first: --config, the --configfile files last to first, the default.
CONFIG_LAYERS = [("--config", dict(workflow.config_settings.config))] + [
    (_shown(f), load_configfile(str(f)) or {}) for f in reversed(list(workflow.config_settings.configfiles))
]


def config_source(*key_path) -> str:
    """The file or command-line option that set a config key (config/config.yaml unless overridden)."""
    return config_origin(key_path, CONFIG_LAYERS, "config/config.yaml")


try:
    # one short message naming the file or option, the key and the value; then Snakemake's own validation
    check_config(config, _SCHEMAS / "config.schema.yaml", "config/config.yaml", CONFIG_LAYERS)
    validate(config, "../schemas/config.schema.yaml")
    _subjects_path = Path(config["subjects"])
    if not _subjects_path.is_file():
        raise LoperInputError(f"{config_source('subjects')}: key 'subjects': file '{_subjects_path}' not found")
    subjects = read_subject_sheet(_subjects_path)
    check_table(subjects, _SCHEMAS / "subjects.schema.yaml", str(_subjects_path))
    validate(subjects, "../schemas/subjects.schema.yaml")
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None
if subjects["subject"].duplicated().any():
    dup = subjects.loc[subjects["subject"].duplicated(), "subject"].iloc[0]
    raise WorkflowError(f"{_subjects_path}: subject '{dup}' appears twice")

SUBJECT_SOURCE = dict(zip(subjects["subject"], subjects["source"]))
#: subject -> {column: value} of the subject sheet, empty cells left out; a synthetic subject's missing
#: anthropometrics drawn from the study's subjects (loper_analysis.synthetic.subjects)
SUBJECT_ROWS = {
    r["subject"]: {k: v for k, v in r.items() if not (isinstance(v, float) and pd.isna(v))}
    for r in subjects.to_dict("records")
}
try:
    for _s, _row in SUBJECT_ROWS.items():
        if _row["source"] == "synthetic":
            _row.update(subject_anthropometry(_row, config["seed"]))
            # the truth must lie inside the identification bounds: checked before any work starts
            true_impedance(
                _s,
                config["seed"],
                config["synthetic"]["stiffness_nm_per_rad"],
                config["synthetic"]["damping_nms_per_rad"],
                config["synthetic"]["between_subject_cv"],
                config["identification"]["stiffness_bounds_nm_per_rad"],
                config["identification"]["damping_bounds_nms_per_rad"],
            )
        elif "model_osim" in _row:  # an already scaled model: no static trial, no scaling
            if not Path(_row["model_osim"]).is_file():
                raise LoperInputError(
                    f"{_subjects_path}: subject '{_s}', column model_osim: file " f"'{_row['model_osim']}' not found"
                )
        elif not raw_file_present(
            Path("data/raw") / _s / f"{config['trials']['static']}.c3d", f"static trial of subject '{_s}'"
        ):
            raise LoperInputError(
                f"{_subjects_path}: recorded subject '{_s}' has no static trial "
                f"data/raw/{_s}/{config['trials']['static']}.c3d (raw files are named data/raw/{{subject}}/{{trial}}.c3d),"
                " nor a scaled model (column model_osim)"
            )
        elif config["opensim"]["generic_model"] is None and "height_m" not in _row:
            raise LoperInputError(
                f"{_subjects_path}: recorded subject '{_s}' needs height_m: the generated model "
                f"({config_source('opensim', 'generic_model')}: opensim.generic_model null) is built from height "
                "(a lab's model, such as gait2392, needs none)"
            )
    _onsets = {int(o) for o in config["synthetic"]["stiffness_nm_per_rad"]}
    if (
        any(r["source"] == "synthetic" for r in SUBJECT_ROWS.values())
        and not set(config["trials"]["perturbation_onsets_ms"]) <= _onsets
    ):
        raise LoperInputError(
            f"{config_source('synthetic', 'stiffness_nm_per_rad')}: key 'synthetic.stiffness_nm_per_rad': "
            f"no truth for onset(s) "
            f"{sorted(set(config['trials']['perturbation_onsets_ms']) - _onsets)} ms of trials.perturbation_onsets_ms"
        )
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None
if config["device"]["subject"] is not None and config["device"]["subject"] not in SUBJECT_SOURCE:
    raise WorkflowError(
        f"{config_source('device', 'subject')}: key 'device.subject': subject '{config['device']['subject']}' "
        f"is not in {_subjects_path}"
    )
_synthetic = [s for s, src in SUBJECT_SOURCE.items() if src == "synthetic"]
SYNTHETIC_PATTERN = "|".join(_synthetic) if _synthetic else "(?!)"

VALIDATION_CHUNKS = [f"{i:03d}" for i in range(config["validation"]["n_chunks"])]


wildcard_constraints:
    subject=r"[A-Za-z0-9-]+",
    chunk=r"[0-9]{3}",
    onset=r"[0-9]{3}",
    trial=r"[A-Za-z0-9-]+",


#: The study's trials, their names and onsets (loper_analysis.study_design).
DESIGN = StudyDesign.from_config(config["trials"])


def subject_trials(subject: str) -> list[str]:
    """Walking trials of a subject: all for a synthetic one, those with a raw C3D on disk for a recorded one."""
    if SUBJECT_SOURCE[subject] == "synthetic":
        return DESIGN.walking_trials()
    raw = Path("data/raw") / subject
    return [t for t in DESIGN.walking_trials() if (raw / f"{t}.c3d").is_file()]


try:
    # a recorded subject's raw files: a path that is not a readable file stops the run (never a trial silently
    # left out); files that match no trial of the design are named in a warning
    for _s in (s for s, src in SUBJECT_SOURCE.items() if src == "recorded"):
        _raw = Path("data/raw") / _s
        for _t in DESIGN.trials():
            for _suffix in RAW_SUFFIXES:
                raw_file_present(_raw / f"{_t}{_suffix}", f"raw file of trial '{_t}' of subject '{_s}'")
        refuse_miscased_raw_files(_raw, DESIGN.trials())
        _unmatched = unmatched_raw_files(_raw, DESIGN.trials())
        if _unmatched:
            _t = config["trials"]
            print(
                f"warning: {_raw}: {', '.join(_unmatched)}: no trial of the design has this name, not analysed "
                f"(trials: {', '.join(DESIGN.trials())}; from trials.static, trials.no_device, trials.device, "
                f"trials.perturbation_onsets_ms {_t['perturbation_onsets_ms']} and trials.perturbation_repeats "
                f"{_t['perturbation_repeats']})",
                file=sys.stderr,
            )
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None


def processed_subjects() -> list[str]:
    """Synthetic subjects, and recorded subjects with a static trial on disk or a scaled model: their walking trials
    are processed."""
    static = config["trials"]["static"]
    return [
        s
        for s, src in SUBJECT_SOURCE.items()
        if src == "synthetic" or "model_osim" in SUBJECT_ROWS[s] or (Path("data/raw") / s / f"{static}.c3d").is_file()
    ]


def trial_label_maps(trial: str) -> list:
    """The label maps of a trial, merged in this order: markers.label_map, then its kind's and its own from
    markers.trial_label_maps (each inline or a file)."""
    per_trial = config["markers"]["trial_label_maps"]
    maps = [config["markers"]["label_map"], per_trial.get(DESIGN.kind(trial)), per_trial.get(trial)]
    return [m for m in maps if m]


def label_map_files(wildcards) -> list[str]:
    """The label-map files among a trial's maps (inputs, so that a changed file reruns the trial)."""
    return [m for m in trial_label_maps(wildcards.trial) if isinstance(m, str)]


def trial_span_s(subject: str, trial: str) -> list[float] | None:
    """The part of a trial analysed, [start, end] in s on the file's clock (markers.trial_spans_s), or None."""
    spans = config["markers"]["trial_spans_s"]
    return spans.get(f"{subject}/{trial}", spans.get(trial))


def scaled_subjects() -> list[str]:
    """Processed subjects whose model is scaled here from their static trial (no model_osim)."""
    return [s for s in processed_subjects() if "model_osim" not in SUBJECT_ROWS[s]]


@cache
def has_force_platforms(subject: str, trial: str) -> bool:
    """Whether a recorded trial's C3D has force platforms (its GRF as OpenSim external loads is made).

    A file with one vertical-force channel per belt instead (events.grf_channels) gives its events from
    those channels and no external loads: said once in a note.
    """
    path = Path("data/raw") / subject / f"{trial}.c3d"
    try:
        if force_platforms_used(path):
            return True
    except LoperInputError as exc:
        raise WorkflowError(str(exc)) from None
    print(
        f"note: {path}: no force platforms (FORCE_PLATFORM:USED 0 or absent): events from the belt channels "
        f"(events.grf_channels: {config['events']['grf_channels']}), no OpenSim external loads "
        f"(results/grf/{subject}/{trial}.grf.mot) for this trial",
        file=sys.stderr,
    )
    return False


def transparency_subjects() -> list[str]:
    """Processed subjects with both walking trials of the transparency experiment."""
    pair = {config["trials"]["no_device"], config["trials"]["device"]}
    return [s for s in processed_subjects() if pair <= set(subject_trials(s))]


def processing_targets() -> list[str]:
    """Stride tables of every processed trial, the segment tables and the transparency analysis."""
    out = []
    for s in processed_subjects():
        out.append(f"results/model/{s}/segments.tsv")
        if s in scaled_subjects():
            out.append(f"results/model/{s}/scale.tsv")
        if SUBJECT_SOURCE[s] == "synthetic":
            out.append(f"data/raw/{s}/truth.yaml")
        out += [f"results/strides/{s}/{t}.strides.tsv" for t in subject_trials(s)]
        if SUBJECT_SOURCE[s] == "recorded":  # lab files: their force platforms as OpenSim external loads
            plated = [t for t in subject_trials(s) if has_force_platforms(s, t)]
            out += [f"results/grf/{s}/{t}.grf.mot" for t in plated]
            out += recorded_figures(s)
    if out:
        out.append("results/strides/summary.tsv")
    if any(DESIGN.onset_ms(t) is not None for s in processed_subjects() for t in subject_trials(s)):
        out += [
            "results/impedance/impedance.tsv",
            "results/impedance/summary.tsv",
            "results/impedance/literature.tsv",
            "results/impedance/impedance.png",
            "results/report/tables.md",
        ]
        out += [f"results/impedance/{s}/{f}.png" for s in processed_subjects() for f in ("responses", "fit")]
        out += ["results/planning/plan.tsv", "results/planning/answers.txt"]
    if transparency_subjects():
        out += [
            "results/transparency/rmsd.tsv",
            "results/transparency/force.tsv",
            "results/transparency/transparency.png",
        ]
    return out


def recorded_figures(subject: str) -> list[str]:
    """A recorded subject's quality figures: joint angles over the gait cycle of every walking trial, force plates
    and events of every trial with plates."""
    trials = subject_trials(subject)
    out = [f"results/strides/{subject}/{t}.angles.png" for t in trials]
    return out + [f"results/grf/{subject}/{t}.grf.png" for t in trials if has_force_platforms(subject, t)]


def all_targets() -> list[str]:
    """Everything `snakemake` builds by default: the validation study only for a study that identifies impedance
    (its perturbation trials) or has no subject, so a gait study's report needs none of it."""
    return [
        *processing_targets(),
        *validation_targets(),
        *device_targets(),
        "results/report/front_page.html",
    ]


def validation_targets() -> list[str]:
    """The validation study's tables and figure: for a study with perturbation trials, or without subjects."""
    targets = processing_targets()
    if targets and "results/impedance/impedance.tsv" not in targets:
        return []
    return [
        "results/validation/summary.tsv",
        "results/validation/errors.tsv",
        "results/validation/fits.tsv",
        "results/validation/errors.png",
    ]


def device_targets() -> list[str]:
    """The device tests' results: none without a device subject (device.subject null)."""
    if config["device"]["subject"] is None:
        return []
    return ["results/device/summary.tsv", "results/device/bode.png", "results/device/steps.png"]


def _raw_partition(resource) -> str | None:
    """A slurm_partition given as plain text in a profile or on the command line (None for a function)."""
    raw = getattr(resource, "raw", None)
    return raw.strip("'\"") if isinstance(raw, str) else None


onstart:
    # a SLURM run: check sbatch and the partitions before the first submission (loper_analysis.cluster)
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        _settings = workflow.resource_settings
        _requested = {}
        if _settings.default_resources is not None and "slurm_partition" in _settings.default_resources.keys():
            _requested["default-resources"] = _raw_partition(_settings.default_resources.get("slurm_partition"))
        for _rule, _res in _settings.overwrite_resources.items():
            if "slurm_partition" in _res.keys():
                _requested[f"set-resources {_rule}"] = _raw_partition(_res.get("slurm_partition"))
        try:
            check_slurm_submission({k: v for k, v in _requested.items() if v is not None})
        except LoperInputError as exc:
            raise WorkflowError(str(exc)) from None


onsuccess:
    # what the run found wrong, on the console (each also in its job's log and in its table)
    from loper_analysis.steps.report import run_warnings

    _said = run_warnings("results/strides/summary.tsv", [f"results/model/{s}/scale.tsv" for s in scaled_subjects()])
    if _said:
        print("warnings of this run's results:", *(f"  {line}" for line in _said), sep="\n", file=sys.stderr)


onerror:
    # a SLURM run: say which failed jobs SLURM itself ended, and why (memory, time limit, cancel)
    if workflow.executor_plugin is not None and workflow.executor_plugin.name == "slurm":
        from loper_analysis.steps.cluster import slurm_failure_lines

        for _path in [log] if isinstance(log, (str, Path)) else log:  # Snakemake 9 passes a list of logs
            for _line in slurm_failure_lines(_path):
                print(_line, file=sys.stderr)
