from loper_analysis.steps import model, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    model.segments(snakemake.input[0], snakemake.output[0], p.side, p.height_m, p.mass_kg, p.user_model)
