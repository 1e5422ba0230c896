# The experiment planner: predicted 95 % CI half-width of K and D from a pilot subject's null pairs and fits.

# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    planning,


PLAN = config["planning"]


def planning_pilot() -> str:
    """The pilot subject: planning.pilot_subject, else the first processed subject."""
    pilot = PLAN["pilot_subject"]
    if pilot is None:
        return processed_subjects()[0]
    if pilot not in processed_subjects():
        raise WorkflowError(f"{config_source('planning', 'pilot_subject')}: key 'planning.pilot_subject': "
                            f"subject '{pilot}' is not a processed subject of {config['subjects']}")
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


rule planning:
    input:
        unpack(planning_inputs),
    output:
        table=report(
            "results/planning/plan.tsv",
            caption="../report/planning_table.rst",
            category="Planning",
            labels={"table": "predicted 95 % CI half-width of K and D"},
        ),
        answers="results/planning/answers.txt",
    params:
        subject=lambda wc: planning_pilot(),
        trials=lambda wc: null_pair_trials(planning_pilot()),
        onsets=TRIALS["perturbation_onsets_ms"],
        strides=PLAN["strides"],
        targets=PLAN["targets"],
        pulse_force_n=PLAN["pulse_force_n"],
        pulse_duration_s=PLAN["pulse_duration_s"],
        response=dict(
            window_before_s=IDENT["window_before_s"],
            window_after_s=IDENT["window_after_s"],
            initial_state_span_s=IDENT["initial_state_span_s"],
            whisker=config["strides"]["iqr_whisker"],
            max_fraction=config["strides"]["max_outlier_fraction"],
        ),
        identification={k: IDENT[k] for k in ("window_before_s", "window_after_s", "initial_state_span_s",
                                                "initial_state_degree", "n_substeps", "null_pair_components",
                                                "min_null_pairs", "max_null_trial_ratio", "interval_scatter",
                                                "stiffness_bounds_nm_per_rad", "damping_bounds_nms_per_rad")},
        device=config["device"]["parameters"],
    log:
        "results/logs/planning/plan.log",
    benchmark:
        "results/benchmarks/planning/plan.tsv"
    script:
        "../scripts/planning.py"
