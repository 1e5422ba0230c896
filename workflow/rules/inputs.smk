# The rules' settings (SETTINGS, built in common.smk by each stage's reader) and their input functions: each asks
# STUDY (loper_analysis.layout).

import dataclasses

IK_CHUNKS = [f"{i:03d}" for i in range(SETTINGS["ik"].n_chunks)]
ONSETS = [f"{o:03d}" for o in DESIGN.perturbation_onsets_ms]


def settings_params(settings, name: str = "settings") -> dict:
    """A rule's params for a settings object (or a function of the wildcards giving one): ``name`` itself (passed
    on by the script) and ``{name}_repr``, its repr: Snakemake's params trigger compares only builtin values (a
    dataclass is left out), so the repr is what makes a changed setting rerun the rule."""
    if callable(settings):
        return {name: settings, f"{name}_repr": lambda wildcards: repr(settings(wildcards))}
    return {name: settings, f"{name}_repr": repr(settings)}


def fit_bounds(end: int) -> tuple[float, float]:
    """The fit's (stiffness, damping) bound at ``end`` 0 (lower) or 1 (upper), N·m/rad and N·m·s/rad."""
    fit = SETTINGS["impedance"].identification
    return (fit.stiffness_bounds_nm_per_rad[end], fit.damping_bounds_nms_per_rad[end])


def label_map_files(wildcards) -> list[str]:
    """The label-map files among a trial's maps (inputs, so that a changed file reruns the trial)."""
    return [m for m in STUDY.label_maps(wildcards.trial) if isinstance(m, str)]


def marker_settings(wildcards):
    """A trial's marker settings: its label maps and span; the static trial neither filled nor filtered."""
    settings = SETTINGS["markers"].for_trial(wildcards.subject, wildcards.trial, DESIGN.kind(wildcards.trial))
    return settings.for_static() if wildcards.trial == DESIGN.static else settings


def event_settings(wildcards):
    """A trial's event settings: the config's with the trial's label maps."""
    return dataclasses.replace(SETTINGS["events"].events, label_map=tuple(STUDY.label_maps(wildcards.trial)) or None)


def ik_settings(wildcards):
    """A subject's IK settings: the marker geometry judged against a model scaled here (a stop) or given in the
    subject sheet (a warning)."""
    return dataclasses.replace(SETTINGS["ik"], subjects_model="model_osim" not in SUBJECT_ROWS[wildcards.subject])


def trial_group(wildcards) -> str:
    """Cluster job group (ignored locally): a walking trial's markers, IK, events and strides run as one SLURM
    job ("trial"); the static trial's markers join the subject's scaling ("model")."""
    return "model" if wildcards.trial == DESIGN.static else "trial"


def raw_checksums(*files) -> dict:
    """The param that reruns a job reading raw files when their content changed, even when a copy kept an older
    time (``cp -p``): the content checksums of ``files`` (path patterns or functions of the wildcards) of
    recorded subjects; generated raw files are the workflow's own outputs, rerun by it."""

    def checksums(wildcards) -> dict[str, str]:
        paths = []
        for item in files:
            value = item(wildcards) if callable(item) else item.format(**wildcards)
            paths += [value] if isinstance(value, str) else list(value)
        return STUDY.recorded_checksums(paths)

    return {"raw_sha256": checksums}


def by_subject(method):
    """An input function of the wildcards from a STUDY method of the subject."""
    return lambda wildcards: method(wildcards.subject)


def by_trial(method):
    """An input function of the wildcards from a STUDY method of the subject and trial."""
    return lambda wildcards: method(wildcards.subject, wildcards.trial)


def planning_pilot() -> str:
    """The pilot subject: planning.pilot_subject, else the first processed subject."""
    try:
        return STUDY.planning_pilot(config_source("planning", "pilot_subject"))
    except LoperInputError as exc:
        raise WorkflowError(str(exc)) from None
