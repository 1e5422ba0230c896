from loper_analysis.steps import model, rule_log

with rule_log(snakemake.log[0]):
    model.scaled_model(snakemake.input.generic, snakemake.input.static, snakemake.output[0], snakemake.params.mass_kg)
