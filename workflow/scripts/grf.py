from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import grf

    i = snakemake.input
    grf.trial_grf(i.c3d, snakemake.output[0], i.markers, snakemake.params.settings)
