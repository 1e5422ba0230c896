from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p = snakemake.params
    processing.loadcell(snakemake.input.c3d, snakemake.input.log, snakemake.output.force, p.sync_channel, p.cutoff_hz,
                        p.order, native_out=snakemake.output.native)
