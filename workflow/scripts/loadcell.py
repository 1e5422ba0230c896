from loper_analysis.steps import processing, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    processing.loadcell(snakemake.input.c3d, snakemake.input.log, snakemake.output[0], p.sync_channel, p.cutoff_hz,
                        p.order)
