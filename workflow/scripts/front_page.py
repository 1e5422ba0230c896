from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import report

    p = snakemake.params
    report.front_page(
        report.FrontPageFiles(**snakemake.input),
        snakemake.output[0],
        p.subjects,
        p.trials,
        p.settings,
        recorded=p.recorded,
    )
