from loper_analysis.steps import model, rule_log

with rule_log(snakemake.log[0]):
    model.generic_model(snakemake.output[0], snakemake.params.height_m, snakemake.params.mass_kg)
