from loper_analysis.steps import impedance, rule_log

with rule_log(snakemake.log[0]):
    impedance.impedance_table(snakemake.input, snakemake.output[0])
