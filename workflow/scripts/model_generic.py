from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import model

    p = snakemake.params
    model.generic_model(
        snakemake.output[0], p.height_m, p.mass_kg, (snakemake.input.static_c3d or [None])[0], p.settings
    )
