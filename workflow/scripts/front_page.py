from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.report import step as report

    p = snakemake.params
    report.front_page(
        report.FrontPageFiles(**snakemake.input),
        snakemake.output[0],
        p.subjects,
        p.trials,
        p.settings,
        recorded=p.recorded,
    )
