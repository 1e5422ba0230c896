# Inverse dynamics: hip, knee and ankle moments and powers of the trials with force platforms.

from loper_analysis.stages.dynamics.files import dynamics_files, dynamics_trials, trials_without


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    dynamics_trials,


rule dynamics:
    """Each foot's load from the plates of its clean contacts, OpenSim's inverse dynamics on the subject's model
    and the IK coordinates, the moments and powers signed as our angles, per gait cycle."""
    input:
        unpack(lambda wc: vars(dynamics_files(STUDY, wc.subject, wc.trial))),
    output:
        moments=PATHS.dynamics.moments,
        cycles=PATHS.dynamics.cycles,
        summary=PATHS.dynamics.summary,
        figure=report(
            PATHS.dynamics.figure,
            caption="../report/dynamics_figure.rst",
            category="Processing",
            subcategory="{subject}",
            labels={"subject": "{subject}", "trial": "{trial}", "figure": "joint moments and powers"},
        ),
    log:
        PATHS.log("dynamics", "{subject}/{trial}"),
    benchmark:
        PATHS.benchmark("dynamics", "{subject}/{trial}")
    params:
        **settings_params(SETTINGS["dynamics"]),
    script:
        "../scripts/dynamics.py"


rule dynamics_trials:
    """Every processed trial: inverse dynamics computed (its cycles per side) or not, and why."""
    input:
        [fill(PATHS.dynamics.cycles, subject=s, trial=t) for s, t in dynamics_trials(STUDY)],
    output:
        report(
            PATHS.dynamics.trials,
            caption="../report/dynamics_trials.rst",
            category="Processing",
            labels={"table": "inverse dynamics per trial"},
        ),
    log:
        PATHS.log("dynamics_trials", "trials"),
    benchmark:
        PATHS.benchmark("dynamics_trials", "trials")
    params:
        trials=dynamics_trials(STUDY),
        without=trials_without(STUDY),
    script:
        "../scripts/dynamics_trials.py"
