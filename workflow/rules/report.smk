# The report: its front page (what was run, the headline numbers and the main figure, as one HTML fragment
# that workflow/report/workflow.rst pulls in above the methods text) and every result table in Markdown.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    front_page,
    tables_markdown,


rule front_page:
    input:
        unpack(front_page_inputs),
    output:
        "results/report/front_page.html",
    log:
        "results/logs/front_page/front_page.log",
    benchmark:
        "results/benchmarks/front_page/front_page.tsv"
    params:
        **settings_params(FRONT_PAGE_SETTINGS),
        subjects=SUBJECT_SOURCE,
        trials={s: subject_trials(s) for s in processed_subjects()},
        recorded=recorded_quality_files(),
    script:
        "../scripts/front_page.py"


rule tables_markdown:
    input:
        list(markdown_sections().values()),
    output:
        "results/report/tables.md",
    log:
        "results/logs/tables_markdown/tables.log",
    benchmark:
        "results/benchmarks/tables_markdown/tables.tsv"
    params:
        headings=list(markdown_sections()),
    script:
        "../scripts/tables_markdown.py"
