# The report: its front page (what was run, the headline numbers and the main figure, as one HTML fragment
# that workflow/report/workflow.rst pulls in above the methods text) and every result table in Markdown.


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    front_page,
    tables_markdown,


rule front_page:
    input:
        unpack(lambda wc: STUDY.front_page_inputs()),
    output:
        PATHS.report.front_page,
    log:
        PATHS.log("front_page", "front_page"),
    benchmark:
        PATHS.benchmark("front_page", "front_page")
    params:
        **settings_params(FRONT_PAGE_SETTINGS),
        subjects=SUBJECT_SOURCE,
        trials={s: STUDY.subject_trials(s) for s in STUDY.processed_subjects()},
        recorded=STUDY.recorded_quality_files(),
    script:
        "../scripts/front_page.py"


rule tables_markdown:
    input:
        list(STUDY.markdown_sections().values()),
    output:
        PATHS.report.tables,
    log:
        PATHS.log("tables_markdown", "tables"),
    benchmark:
        PATHS.benchmark("tables_markdown", "tables")
    params:
        headings=list(STUDY.markdown_sections()),
    script:
        "../scripts/tables_markdown.py"
