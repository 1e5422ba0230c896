# The report: its front page (what was run, the headline numbers and the main figure, as one HTML fragment
# that workflow/report/workflow.rst pulls in above the methods text) and every result table in Markdown. The front
# page's inputs include the calibration table its truth verdicts rest on (report.calibration, with synthetic subjects).

from loper_analysis.stages import report_tables
from loper_analysis.stages.report.files import front_page_inputs, recorded_quality_files


# small jobs (gathers, tables, figures, a second or less of work each): on a cluster they run in the
# controlling process instead of paying a SLURM job's start-up
localrules:
    front_page,
    tables_markdown,


rule front_page:
    input:
        unpack(lambda wc: front_page_inputs(STUDY)),
    output:
        PATHS.report.front_page,
    log:
        PATHS.log("front_page", "front_page"),
    benchmark:
        PATHS.benchmark("front_page", "front_page")
    params:
        **settings_params(SETTINGS["report"]),
        subjects=SUBJECT_SOURCE,
        trials={s: STUDY.subject_trials(s) for s in STUDY.processed_subjects()},
        recorded=recorded_quality_files(STUDY),
    script:
        "../scripts/front_page.py"


rule tables_markdown:
    input:
        list(report_tables(STUDY).values()),
    output:
        PATHS.report.tables,
    log:
        PATHS.log("tables_markdown", "tables"),
    benchmark:
        PATHS.benchmark("tables_markdown", "tables")
    params:
        headings=list(report_tables(STUDY)),
    script:
        "../scripts/tables_markdown.py"
