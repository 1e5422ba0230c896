from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.strides import step as strides

    i = snakemake.input
    strides.angles_figure(i.angles, i.events, snakemake.output[0], i.lab_angles, title=snakemake.params.title)
