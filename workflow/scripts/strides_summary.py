from loper_analysis.steps import processing, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    processing.strides_summary(p.subject_trial, snakemake.input.strides, snakemake.output[0], p.min_valid,
                               snakemake.input.contacts)
