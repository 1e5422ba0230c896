from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import validation

    validation.validation_figure(snakemake.input.errors, snakemake.output[0])
