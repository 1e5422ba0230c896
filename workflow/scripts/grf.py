from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.grf import step as grf

    i = snakemake.input
    grf.trial_grf(i.c3d, snakemake.output[0], i.markers, snakemake.params.settings)
