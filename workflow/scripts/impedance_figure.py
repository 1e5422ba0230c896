from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.impedance import step as impedance

    impedance.impedance_figure(snakemake.input[0], snakemake.output[0])
