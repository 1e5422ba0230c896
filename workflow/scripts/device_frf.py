from loper_analysis.steps import device, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    device.frf(snakemake.input[0], snakemake.output[0], p.sample_rate_hz, p.window_samples, p.overlap_samples)
