from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import model

    p = snakemake.params
    model.scale(snakemake.input.generic, snakemake.input.static, snakemake.output[0], p.mass_kg, p.scale_setup,
                p.segment_bodies, tuple(p.factor_range))
