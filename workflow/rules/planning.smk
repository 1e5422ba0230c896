# The experiment planner: predicted 95 % CI half-width of K and D from a pilot subject's null pairs and fits.

from loper_analysis.steps.planning import planning_settings


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    planning,


PLAN = config["planning"]
#: onsets, strides, targets, pulse, response, identification and device settings: the mapping of config keys that
#: ``loper-analysis plan`` takes too (one function, so that the command and the rule cannot drift apart)
PLAN_SETTINGS = planning_settings(config)


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
    log:
        "results/logs/planning/plan.log",
    benchmark:
        "results/benchmarks/planning/plan.tsv"
    params:
        **PLAN_SETTINGS,
        subject=lambda wc: planning_pilot(),
        trials=lambda wc: null_pair_trials(planning_pilot()),
    script:
        "../scripts/planning.py"
