from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.grf import step as grf

    i = snakemake.input
    grf.grf_figure(i.grf, i.events, snakemake.output[0], title=snakemake.params.title)
