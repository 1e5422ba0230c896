from loper_analysis.steps import device, rule_log

with rule_log(snakemake.log[0]):
    device.summary(snakemake.input.frf, snakemake.input.metrics, snakemake.output[0], snakemake.params.reference_band_hz)
