from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p = snakemake.params
    processing.strides_summary(p.subject_trial, snakemake.input.strides, snakemake.output[0], p.min_valid,
                               snakemake.input.contacts)
