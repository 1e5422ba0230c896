from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.report import step as report

    report.markdown_tables(snakemake.params.headings, snakemake.input, snakemake.output[0])
