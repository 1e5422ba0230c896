from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import report

    report.markdown_tables(snakemake.params.headings, snakemake.input, snakemake.output[0])
