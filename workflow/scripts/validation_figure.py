from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.validation import step as validation

    validation.validation_figure(snakemake.input.errors, snakemake.output[0])
