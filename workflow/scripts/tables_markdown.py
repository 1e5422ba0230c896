from loper_analysis.steps import report, rule_log

with rule_log(snakemake.log[0]):
    report.markdown_tables(snakemake.params.headings, snakemake.input, snakemake.output[0])
