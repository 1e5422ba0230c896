# The experiment planner: predicted 95 % CI half-width of K and D from a pilot subject's null pairs and fits.

from loper_analysis.stages.planning.files import planning_files


def planning_pilot() -> str:
    """The pilot subject: planning.pilot_subject, else the first processed subject."""
    try:
        return STUDY.planning_pilot(config_source("planning", "pilot_subject"))
    except LoperInputError as exc:
        raise WorkflowError(str(exc)) from None


def planning_inputs(wildcards) -> list[str]:
    """Every file the planner reads."""
    files = planning_files(STUDY, planning_pilot())
    tables = [path for trial in files.trials.values() for path in (trial.angles, trial.strides)]
    return [*tables, files.segments, *files.impedance]


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    planning,


rule planning:
    input:
        planning_inputs,
    output:
        table=report(
            PATHS.planning.plan,
            caption="../report/planning_table.rst",
            category="Planning",
            labels={"table": "predicted 95 % CI half-width of K and D"},
        ),
        answers=PATHS.planning.answers,
    log:
        PATHS.log("planning", "plan"),
    benchmark:
        PATHS.benchmark("planning", "plan")
    params:
        **settings_params(PLAN_SETTINGS),
        files=lambda wc: planning_files(STUDY, planning_pilot()),
        subject=lambda wc: planning_pilot(),
    script:
        "../scripts/planning.py"
