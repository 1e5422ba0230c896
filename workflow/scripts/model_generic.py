from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import model

    model.generic_model(snakemake.output[0], snakemake.params.height_m, snakemake.params.mass_kg)
