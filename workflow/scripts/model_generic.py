from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.model import step as model

    p = snakemake.params
    model.generic_model(
        snakemake.output[0], p.height_m, p.mass_kg, (snakemake.input.static_c3d or [None])[0], p.settings
    )
