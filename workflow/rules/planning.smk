# The experiment planner: predicted 95 % CI half-width of K and D from a pilot subject's null pairs and fits.

from loper_analysis.stages.planning.files import planning_files, planning_inputs


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    planning,


rule planning:
    input:
        lambda wc: planning_inputs(STUDY, planning_pilot()),
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
        **settings_params(SETTINGS["planning"]),
        files=lambda wc: planning_files(STUDY, planning_pilot()),
        subject=lambda wc: planning_pilot(),
    script:
        "../scripts/planning.py"
