# The rules' settings from the config and their input functions: the stage files only wire them.

import dataclasses

from loper_analysis.steps.events import EventSettings, LoadcellSettings
from loper_analysis.steps.grf import GRFSettings
from loper_analysis.steps.ik import IKSettings
from loper_analysis.steps.markers import MarkerSettings
from loper_analysis.steps.model import ModelSettings
from loper_analysis.steps.strides import StrideSettings
from loper_analysis.steps.impedance import FitFiles, FitOutputs, FitSettings, TrialFiles
from loper_analysis.steps.planning import PilotFiles, PilotTrial, PlanningSettings
from loper_analysis.steps.report import FrontPageSettings
from loper_analysis.steps.transparency import TransparencyFiles, TransparencySettings

# the config's sections
TRIALS = config["trials"]
MARKERS = config["markers"]
FILTER = config["filter"]
OPENSIM = config["opensim"]
EVENTS = config["events"]
IDENT = config["identification"]
PLAN = config["planning"]
DEVICE = config["device"]
SYNTH = config["synthetic"]

DEVICE_SUBJECT = DEVICE["subject"]
DEVICE_RATE_HZ = DEVICE["parameters"]["sample_rate_hz"]
IK_CHUNKS = [f"{i:03d}" for i in range(OPENSIM["ik_chunks"])]
ONSETS = [f"{o:03d}" for o in TRIALS["perturbation_onsets_ms"]]

# the settings of the stages' rules
MODEL_SETTINGS = ModelSettings.from_config(config)
IK_SETTINGS = IKSettings.from_config(config)
GRF_SETTINGS = GRFSettings.from_config(config)
MARKER_SETTINGS = MarkerSettings.from_config(config)
EVENT_SETTINGS = EventSettings.from_config(config)
LOADCELL_SETTINGS = LoadcellSettings.from_config(config)
STRIDE_SETTINGS = StrideSettings.from_config(config)
try:
    FIT_SETTINGS = FitSettings.from_config(config)
    TRANSPARENCY_SETTINGS = TransparencySettings.from_config(config)
    FRONT_PAGE_SETTINGS = FrontPageSettings.from_config(config)
    #: onsets, strides, targets, pulse, response, identification and device settings: what ``loper-analysis
    #: plan`` builds too (one classmethod, so that the command and the rule cannot drift apart)
    PLAN_SETTINGS = PlanningSettings.from_config(config)
except LoperInputError as exc:
    raise WorkflowError(str(exc)) from None


def settings_params(settings, name: str = "settings") -> dict:
    """A rule's params for a settings object (or a function of the wildcards giving one): ``name`` itself (passed
    on by the script) and ``{name}_repr``, its repr: Snakemake's params trigger compares only builtin values (a
    dataclass is left out), so the repr is what makes a changed setting rerun the rule."""
    if callable(settings):
        return {name: settings, f"{name}_repr": lambda wildcards: repr(settings(wildcards))}
    return {name: settings, f"{name}_repr": repr(settings)}


def marker_settings(wildcards) -> MarkerSettings:
    """A trial's marker settings: its label maps and span; the static trial neither filled nor filtered."""
    span = trial_span_s(wildcards.subject, wildcards.trial)
    settings = dataclasses.replace(
        MARKER_SETTINGS,
        label_map=tuple(trial_label_maps(wildcards.trial)) or None,
        span_s=None if span is None else tuple(span),
    )
    return settings.for_static() if wildcards.trial == TRIALS["static"] else settings


def event_settings(wildcards) -> EventSettings:
    """A trial's event settings: the config's with the trial's label maps."""
    return dataclasses.replace(EVENT_SETTINGS, label_map=tuple(trial_label_maps(wildcards.trial)) or None)


def ik_settings(wildcards) -> IKSettings:
    """A subject's IK settings: the config's, the marker geometry judged against a model scaled here (a stop) or
    given in the subject sheet (a warning)."""
    return dataclasses.replace(IK_SETTINGS, subjects_model="model_osim" not in SUBJECT_ROWS[wildcards.subject])


def subject_model(wildcards):
    """The subject's OpenSim model: user-supplied (subjects.tsv column model_osim) or scaled from the static trial."""
    user = SUBJECT_ROWS[wildcards.subject].get("model_osim")
    return user if user else f"results/model/{wildcards.subject}/scaled.osim"


def trial_group(wildcards) -> str:
    """Cluster job group (ignored locally): a walking trial's markers, IK, events and strides run as one SLURM
    job ("trial"); the static trial's markers join the subject's scaling ("model")."""
    return "model" if wildcards.trial == TRIALS["static"] else "trial"


def generic_model(wildcards):
    """The model scaled per subject: opensim.generic_model, or the generated model for the subject."""
    return OPENSIM["generic_model"] or f"results/model/{wildcards.subject}/generic.osim"


def static_c3d_for_mass(wildcards) -> list[str]:
    """The static trial's C3D when the subject sheet gives no mass or no height (the mass comes from its force
    plates or its PROCESSING:Bodymass, the height from its PROCESSING:Height)."""
    row = SUBJECT_ROWS[wildcards.subject]
    if "mass_kg" in row and "height_m" in row:
        return []
    return [f"data/raw/{wildcards.subject}/{TRIALS['static']}.c3d"]


def raw_checksums(*files) -> dict:
    """The param that reruns a job reading raw files when their content changed, even when a copy kept an older
    time (``cp -p``): the content checksums of ``files`` (path patterns or functions of the wildcards) of
    recorded subjects; generated raw files are the workflow's own outputs, rerun by it."""

    def checksums(wildcards) -> dict[str, str]:
        paths = []
        for item in files:
            value = item(wildcards) if callable(item) else item.format(**wildcards)
            paths += [value] if isinstance(value, str) else list(value)
        return {
            path: content_checksum(path)
            for path in paths
            if Path(path).parts[:2] == ("data", "raw")
            and SUBJECT_SOURCE.get(Path(path).parts[2]) == "recorded"
            and Path(path).is_file()
        }

    return {"raw_sha256": checksums}


def robot_log(wildcards):
    """A trial's robot log: data/raw/{subject}/{trial}.loper.tsv, or converted from the MATLAB export {trial}.mat."""
    raw = Path("data/raw") / wildcards.subject
    if (
        SUBJECT_SOURCE[wildcards.subject] == "recorded"
        and not (raw / f"{wildcards.trial}.loper.tsv").exists()
        and (raw / f"{wildcards.trial}.mat").exists()
    ):
        return f"results/device/{wildcards.subject}/{wildcards.trial}.loper.tsv"
    return str(raw / f"{wildcards.trial}.loper.tsv")


def stride_force(wildcards):
    """The interaction force of a trial walked with the device (none without it)."""
    if wildcards.trial == TRIALS["no_device"]:
        return []
    return f"results/events/{wildcards.subject}/{wildcards.trial}.force.tsv"


def transparency_files() -> dict[str, TransparencyFiles]:
    """Stride and cycle tables of the transparency pair of every subject that walked both trials."""

    def table(s, cond, kind):
        return f"results/strides/{s}/{TRIALS[cond]}.{kind}.tsv"

    return {
        s: TransparencyFiles(
            no_device_strides=table(s, "no_device", "strides"),
            no_device_cycles=table(s, "no_device", "cycles"),
            device_strides=table(s, "device", "strides"),
            device_cycles=table(s, "device", "cycles"),
        )
        for s in transparency_subjects()
    }


def transparency_inputs(wildcards) -> list[str]:
    """Every table of transparency_files."""
    return [path for files in transparency_files().values() for path in dataclasses.astuple(files)]


def device_log(trial):
    """Robot log of a device trial: generated (synthetic), converted from .mat, or as recorded."""
    if DEVICE_SUBJECT is None:  # no device tests in this study: the device rules are never asked for
        return []
    raw = Path("data/raw") / DEVICE_SUBJECT
    if SUBJECT_SOURCE[DEVICE_SUBJECT] == "recorded" and (raw / f"{trial}.mat").exists():
        return f"results/device/{DEVICE_SUBJECT}/{trial}.loper.tsv"
    return str(raw / f"{trial}.loper.tsv")


def onset_trials(subject: str, onset: str) -> list[str]:
    """The subject's trials of one onset that are on disk (or generated)."""
    return [t for t in subject_trials(subject) if DESIGN.onset_ms(t) == int(onset)]


def null_pair_trials(subject: str) -> list[str]:
    """The subject's trials with the device (minimal impedance and perturbation): their unperturbed strides
    are the null pairs of every onset's fit."""
    return [t for t in subject_trials(subject) if t != config["trials"]["no_device"]]


#: The files a subject's fit at one onset writes ({subject}; {onset}: the onset's three digits).
FIT_OUTPUTS = dict(
    response="results/impedance/{subject}/{onset}.response.tsv",
    counts="results/impedance/{subject}/{onset}.counts.tsv",
    fit="results/impedance/{subject}/{onset}.tsv",
    curves="results/impedance/{subject}/{onset}.curves.tsv",
    force="results/impedance/{subject}/{onset}.force.tsv",
)


def fit_files(subject: str) -> dict[int, FitFiles]:
    """Files of a subject's fit at every onset (ms, in the config's order): the onset's own trials (angles,
    strides, the force at 128 Hz and at the robot rate, markers), the null-pair trials (angles, strides), the
    segment table, a synthetic truth and the outputs (FIT_OUTPUTS)."""
    s = subject

    def trial_files(t: str, own: bool) -> TrialFiles:
        tables = dict(angles=f"results/ik/{s}/{t}.angles.tsv", strides=f"results/strides/{s}/{t}.strides.tsv")
        if own:
            tables.update(
                force=f"results/events/{s}/{t}.force.tsv",
                markers=f"results/markers/{s}/{t}.trc",
                force_native=f"results/events/{s}/{t}.force_native.tsv",
            )
        return TrialFiles(**tables)

    return {
        int(o): FitFiles(
            trials={t: trial_files(t, True) for t in onset_trials(s, o)},
            segments=f"results/model/{s}/segments.tsv",
            outputs=FitOutputs(**{kind: path.format(subject=s, onset=o) for kind, path in FIT_OUTPUTS.items()}),
            null_trials={t: trial_files(t, False) for t in fit_null_trials(s, o)},
            truth=f"data/raw/{s}/truth.yaml" if SUBJECT_SOURCE[s] == "synthetic" else None,
        )
        for o in ONSETS
    }


def fit_inputs(wildcards) -> list[str]:
    """Every file a subject's fits read (fit_files), each once."""
    paths = []
    for files in fit_files(wildcards.subject).values():
        paths += [files.segments, *([files.truth] if files.truth else [])]
        for trial in (*files.trials.values(), *files.null_trials.values()):
            paths += [path for path in dataclasses.astuple(trial) if path is not None]
    return list(dict.fromkeys(paths))


def fit_null_trials(subject: str, onset: str) -> list[str]:
    """Null-pair trials of a fit: none for a white-noise fit or a missing onset (reported without any input)."""
    if IDENT["noise_model"] != "null_pairs" or not onset_trials(subject, onset):
        return []
    return null_pair_trials(subject)


def markdown_sections() -> dict:
    """Every result table of the run, for the Markdown rendering."""
    sections = {
        "Impedance per subject, onset and joint": "results/impedance/impedance.tsv",
        "Across-subject summary": "results/impedance/summary.tsv",
        "Literature": "results/impedance/literature.tsv",
        "Strides per trial": "results/strides/summary.tsv",
        "Validation study": "results/validation/summary.tsv",
        "Device": "results/device/summary.tsv",
    }
    if transparency_subjects():
        sections["Transparency: RMSD vs ISV_ave"] = "results/transparency/rmsd.tsv"
        sections["Transparency: interaction force"] = "results/transparency/force.tsv"
    return sections


def planning_pilot() -> str:
    """The pilot subject: planning.pilot_subject, else the first processed subject."""
    pilot = PLAN["pilot_subject"]
    if pilot is None:
        return processed_subjects()[0]
    if pilot not in processed_subjects():
        raise WorkflowError(
            f"{config_source('planning', 'pilot_subject')}: key 'planning.pilot_subject': "
            f"subject '{pilot}' is not a processed subject of {config['subjects']}"
        )
    return pilot


def planning_files() -> PilotFiles:
    """The pilot's angle and stride tables of its trials with the device, its segment table and fit rows."""
    s = planning_pilot()
    return PilotFiles(
        trials={
            t: PilotTrial(angles=f"results/ik/{s}/{t}.angles.tsv", strides=f"results/strides/{s}/{t}.strides.tsv")
            for t in null_pair_trials(s)
        },
        segments=f"results/model/{s}/segments.tsv",
        impedance=tuple(f"results/impedance/{s}/{o:03d}.tsv" for o in TRIALS["perturbation_onsets_ms"]),
    )


def planning_inputs(wildcards) -> list[str]:
    """Every file of planning_files."""
    files = planning_files()
    tables = [path for trial in files.trials.values() for path in (trial.angles, trial.strides)]
    return [*tables, files.segments, *files.impedance]


def front_page_inputs(wildcards) -> dict:
    """Tables the front page reads: the validation summary with the validation study, the device summary with
    device tests, the
    impedance tables and the main figure when the run has perturbation trials, the transparency table when a
    subject walked both trials of the pair (the targets of processing_targets); named as the fields of
    loper_analysis.steps.report.FrontPageFiles."""
    out = {"validation": "results/validation/summary.tsv"} if validation_targets() else {}
    if device_targets():
        out["device"] = "results/device/summary.tsv"
    targets = set(processing_targets())
    if "results/impedance/impedance.tsv" in targets:
        out.update(
            impedance="results/impedance/impedance.tsv",
            summary="results/impedance/summary.tsv",
            figure="results/impedance/impedance.png",
        )
    if "results/transparency/rmsd.tsv" in targets:
        out["rmsd"] = "results/transparency/rmsd.tsv"
    recorded = recorded_quality_files()
    if recorded:
        out["strides"] = "results/strides/summary.tsv"
        out["quality"] = [
            path
            for entry in recorded.values()
            for path in [entry["scale"], *(p for files in entry["trials"].values() for p in files.values())]
            if path is not None
        ]
    return out


def recorded_quality_files() -> dict:
    """The files of the front page's section on recorded subjects: per recorded subject its scale report (None with
    a scaled model from the sheet) and per walking trial its IK summary, agreement with the lab's own angles and
    figures (the force plates' None without plates); loper_analysis.steps.report.front_page's ``recorded``."""
    out = {}
    for s in processed_subjects():
        if SUBJECT_SOURCE[s] != "recorded":
            continue
        trials = {
            t: {
                "ik": f"results/ik/{s}/{t}.ik.tsv",
                "agreement": f"results/ik/{s}/{t}.lab_agreement.tsv",
                "angles_png": f"results/strides/{s}/{t}.angles.png",
                "grf_png": f"results/grf/{s}/{t}.grf.png" if has_force_platforms(s, t) else None,
            }
            for t in subject_trials(s)
        }
        out[s] = {"scale": f"results/model/{s}/scale.tsv" if s in scaled_subjects() else None, "trials": trials}
    return out


# the simulated gait lab's settings (rule synthetic_lab)
from loper_analysis.steps.synthetic import LabSessionSettings

LAB_SESSION_SETTINGS = LabSessionSettings.from_config(config)
