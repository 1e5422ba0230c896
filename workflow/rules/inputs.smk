# The rules' settings from the config and their input functions: the stage files only wire them.

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
STATIC_SETTINGS = dict(duration_s=MARKERS["static_duration_s"], rotation_deg=MARKERS["lab_to_model_rotation_deg"])
IK_SETTINGS = dict(
    tasks_file=OPENSIM["ik_tasks"],
    default_weight=OPENSIM["default_marker_weight"],
    marker_weights=OPENSIM["marker_weights"],
    coordinate_tasks=OPENSIM["coordinate_tasks"],
    accuracy=OPENSIM["accuracy"],
    max_marker_rms_m=OPENSIM["max_marker_rms_m"],
    warn_marker_rms_m=OPENSIM["warn_marker_rms_m"],
    max_rms_fraction=OPENSIM["max_rms_fraction"],
)
EVENT_SETTINGS = dict(
    grf_channels=EVENTS["grf_channels"],
    threshold_on_n=EVENTS["threshold_on_n"],
    threshold_off_n=EVENTS["threshold_off_n"],
    min_stance_s=EVENTS["min_stance_s"],
    min_swing_s=EVENTS["min_swing_s"],
    cutoff_hz=EVENTS["grf_cutoff_hz"],
    order=FILTER["order"],
    foot_markers=EVENTS["foot_markers"],
    plate_sides=EVENTS["plate_sides"],
    rotation_deg=MARKERS["lab_to_model_rotation_deg"],
    band_n=config["grf"]["resting_band_n"],
    max_rest_n=config["grf"]["max_resting_n"],
)
LOADCELL_SETTINGS = dict(sync_channel=EVENTS["sync_channel"], cutoff_hz=FILTER["cutoff_hz"], order=FILTER["order"])
#: onsets, strides, targets, pulse, response, identification and device settings: the mapping of config keys that
#: ``loper-analysis plan`` takes too (one function, so that the command and the rule cannot drift apart)
PLAN_SETTINGS = planning_settings(config)


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
    """The static trial's C3D when the subject sheet gives no mass (the mass comes from its force plates)."""
    if "mass_kg" in SUBJECT_ROWS[wildcards.subject]:
        return []
    return [f"data/raw/{wildcards.subject}/{TRIALS['static']}.c3d"]


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
    return f"results/loadcell/{wildcards.subject}/{wildcards.trial}.force.tsv"


def transparency_inputs(wildcards):
    """Stride and cycle tables of the transparency pair, one list per condition and kind, in subject order."""
    return {
        f"{cond}_{kind}": [f"results/strides/{s}/{TRIALS[cond]}.{kind}.tsv" for s in transparency_subjects()]
        for cond in ("no_device", "device")
        for kind in ("strides", "cycles")
    }


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


def fit_trials(subject: str) -> list[str]:
    """The subject's trials any of its fits reads, in subject_trials order: the onsets' own trials and the
    null-pair trials."""
    used = {t for o in ONSETS for t in onset_trials(subject, o) + fit_null_trials(subject, o)}
    return [t for t in subject_trials(subject) if t in used]


def fit_inputs(wildcards):
    """Files of a subject's fits: angles and strides of every trial a fit reads (order of fit_trials), the force
    at 128 Hz and at the robot rate and the markers of the perturbation trials (order of their onsets' trials),
    the segment table and a synthetic truth."""
    s = wildcards.subject
    out = {"segments": f"results/model/{s}/segments.tsv"}
    if SUBJECT_SOURCE[s] == "synthetic":
        out["truth"] = f"data/raw/{s}/truth.yaml"
    used = fit_trials(s)
    out["angles"] = [f"results/ik/{s}/{t}.angles.tsv" for t in used]
    out["strides"] = [f"results/strides/{s}/{t}.strides.tsv" for t in used]
    own = [t for o in ONSETS for t in onset_trials(s, o)]
    out["force"] = [f"results/loadcell/{s}/{t}.force.tsv" for t in own]
    out["force_native"] = [f"results/loadcell/{s}/{t}.force_native.tsv" for t in own]
    out["markers"] = [f"results/markers/{s}/{t}.trc" for t in own]
    return out


def fit_null_trials(subject: str, onset: str) -> list[str]:
    """Null-pair trials of a fit: none for a white-noise fit or a missing onset (reported without any input)."""
    if IDENT["noise_model"] != "null_pairs" or not onset_trials(subject, onset):
        return []
    return null_pair_trials(subject)


def markdown_sections() -> dict:
    """Every result table of the run, for the Markdown rendering."""
    sections = {
        "Impedance per subject, onset and joint": "results/tables/impedance.tsv",
        "Across-subject summary": "results/tables/impedance_summary.tsv",
        "Literature": "results/tables/literature.tsv",
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


def planning_inputs(wildcards):
    """The pilot's angle and stride tables of its trials with the device, its segment table and fit rows."""
    s = planning_pilot()
    trials = null_pair_trials(s)
    return {
        "angles": [f"results/ik/{s}/{t}.angles.tsv" for t in trials],
        "strides": [f"results/strides/{s}/{t}.strides.tsv" for t in trials],
        "segments": f"results/model/{s}/segments.tsv",
        "impedance": [f"results/impedance/{s}/{o:03d}.tsv" for o in TRIALS["perturbation_onsets_ms"]],
    }


def front_page_inputs(wildcards) -> dict:
    """Tables the front page reads: the validation summary always, the device summary with device tests, the
    impedance tables and the main figure when the run has perturbation trials, the transparency table when a
    subject walked both trials of the pair (the targets of processing_targets)."""
    out = {"validation": "results/validation/summary.tsv"}
    if device_targets():
        out["device"] = "results/device/summary.tsv"
    targets = set(processing_targets())
    if "results/tables/impedance.tsv" in targets:
        out.update(
            impedance="results/tables/impedance.tsv",
            summary="results/tables/impedance_summary.tsv",
            figure="results/figures/impedance.png",
        )
    if "results/transparency/rmsd.tsv" in targets:
        out["rmsd"] = "results/transparency/rmsd.tsv"
    return out


def lab_settings() -> dict:
    """Keyword arguments of loper_analysis.synthetic.trials.LabSettings from the config."""
    return dict(
        marker_noise_sd_m=SYNTH["marker_noise_sd_m"],
        n_gaps=SYNTH["marker_gaps_per_trial"],
        max_gap_frames=SYNTH["max_gap_frames"],
        grf_noise_sd_n=SYNTH["grf_noise_sd_n"],
        clock_offset_s=SYNTH["clock_offset_s"],
        clock_drift_ppm=SYNTH["clock_drift_ppm"],
        lab_to_model_rotation_deg=tuple(config["markers"]["lab_to_model_rotation_deg"]),
        sync_channel=config["events"]["sync_channel"],
    )
