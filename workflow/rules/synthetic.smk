# The simulated gait lab: raw files of synthetic subjects (never of recorded ones, see SYNTHETIC_PATTERN).

SYNTH = config["synthetic"]


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


rule synthetic_static:
    output:
        f"data/raw/{{subject}}/{TRIALS['static']}.c3d",
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
    params:
        row=lambda wc: SUBJECT_ROWS[wc.subject],
        duration_s=SYNTH["static_duration_s"],
        lab=lab_settings(),
        seed=config["seed"],
    log:
        "results/logs/synthetic_static/{subject}.log",
    script:
        "../scripts/synthetic_static.py"


rule synthetic_truth:
    output:
        "data/raw/{subject}/truth.yaml",
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
    params:
        row=lambda wc: SUBJECT_ROWS[wc.subject],
        stiffness=SYNTH["stiffness_nm_per_rad"],
        damping=SYNTH["damping_nms_per_rad"],
        cv=SYNTH["between_subject_cv"],
        stiffness_bounds=config["identification"]["stiffness_bounds_nm_per_rad"],
        damping_bounds=config["identification"]["damping_bounds_nms_per_rad"],
        seed=config["seed"],
    log:
        "results/logs/synthetic_truth/{subject}.log",
    script:
        "../scripts/synthetic_truth.py"


def walking_truth(wildcards):
    """A perturbation trial needs the subject's true impedance."""
    trial = wildcards.get("trial", TRIALS["no_device"])
    return f"data/raw/{wildcards.subject}/truth.yaml" if trial_onset_ms(trial) is not None else []


rule synthetic_walking:
    input:
        truth=walking_truth,
    output:
        c3d="data/raw/{subject}/{trial}.c3d",
        log="data/raw/{subject}/{trial}.loper.tsv",
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
        trial="|".join(t for t in walking_trials() if t != TRIALS["no_device"]),
    params:
        row=lambda wc: SUBJECT_ROWS[wc.subject],
        trial=lambda wc: wc.get("trial", TRIALS["no_device"]),
        onset_ms=lambda wc: trial_onset_ms(wc.get("trial", TRIALS["no_device"])),
        settings=SYNTH,
        lab=lab_settings(),
        device=config["device"]["parameters"],
        seed=config["seed"],
    log:
        "results/logs/synthetic_walking/{subject}/{trial}.log",
    benchmark:
        "results/benchmarks/synthetic_walking/{subject}/{trial}.tsv"
    script:
        "../scripts/synthetic_walking.py"


use rule synthetic_walking as synthetic_walking_no_device with:
    output:
        c3d=f"data/raw/{{subject}}/{TRIALS['no_device']}.c3d",
    wildcard_constraints:
        subject=SYNTHETIC_PATTERN,
    log:
        f"results/logs/synthetic_walking/{{subject}}/{TRIALS['no_device']}.log",
    benchmark:
        f"results/benchmarks/synthetic_walking/{{subject}}/{TRIALS['no_device']}.tsv"
