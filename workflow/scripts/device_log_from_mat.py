from loper_analysis.steps import device, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    device.log_from_mat(snakemake.input[0], snakemake.output[0], p.column_map, p.sample_rate_hz)
