from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.device import step as device

    p, out = snakemake.params, snakemake.output
    device.steps(snakemake.input[0], out.metrics, out.average, p.sample_rate_hz, p.amplitudes_n, p.settings)
