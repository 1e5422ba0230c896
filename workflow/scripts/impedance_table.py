from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    impedance.impedance_table(snakemake.input, snakemake.output[0])
