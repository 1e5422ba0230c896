from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import model

    p, i = snakemake.params, snakemake.input
    model.scale(
        i.generic,
        i.static,
        snakemake.output.model,
        p.mass_kg,
        p.scale_setup,
        p.segment_bodies,
        tuple(p.factor_range),
        lab_labels=i.static_summary,
        static_c3d=(i.static_c3d or [None])[0],
        height_m=p.height_m,
        report_out=snakemake.output.report,
        **p.static,
    )
