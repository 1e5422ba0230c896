# The experiment planner: predicted 95 % CI half-width of K and D from a pilot subject's null pairs and fits.


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
        files=lambda wc: STUDY.planning_files(planning_pilot()),
        subject=lambda wc: planning_pilot(),
    script:
        "../scripts/planning.py"
