from loper_analysis.steps import rule_log, validation

with rule_log(snakemake.log[0]):
    validation.validation_figure(snakemake.input.errors, snakemake.output[0])
