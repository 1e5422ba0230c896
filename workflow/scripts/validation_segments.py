from loper_analysis.steps import model, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    model.anthropometric_segments(snakemake.output[0], p.height_m, p.mass_kg, p.attachment_fraction)
