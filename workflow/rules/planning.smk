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
        **settings_params(PLAN_SETTINGS),
        files=lambda wc: planning_files(),
        subject=lambda wc: planning_pilot(),
    script:
        "../scripts/planning.py"
