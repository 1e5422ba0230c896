from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.device import step as device

    device.summary(
        snakemake.input.frf, snakemake.input.metrics, snakemake.output[0], snakemake.params.reference_band_hz
    )
