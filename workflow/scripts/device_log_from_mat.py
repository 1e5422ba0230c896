from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.device import step as device

    p = snakemake.params
    device.log_from_mat(snakemake.input[0], snakemake.output[0], p.column_map, p.sample_rate_hz)
