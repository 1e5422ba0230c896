from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import grf

    p = snakemake.params
    grf.trial_grf(
        snakemake.input.c3d,
        snakemake.output[0],
        snakemake.input.markers,
        p.rotation_deg,
        p.threshold_n,
        p.band_n,
        p.max_rest_n,
    )
