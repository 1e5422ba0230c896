from _logging import setup

from loper_analysis.device.files import write_device_summary

log = setup(snakemake.log[0])
summary = write_device_summary(
    snakemake.input.frf, snakemake.input.metrics, snakemake.output[0], snakemake.params.reference_band_hz
)
log.info("device summary:\n%s", summary.to_string())
