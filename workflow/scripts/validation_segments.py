from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.validation import step as validation

    p = snakemake.params
    validation.validation_segments(snakemake.output[0], p.height_m, p.mass_kg, p.attachment_fraction)
