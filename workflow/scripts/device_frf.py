from _logging import setup

from loper_analysis.device.files import write_frf_table

log = setup(snakemake.log[0])
p = snakemake.params
frf = write_frf_table(snakemake.input[0], snakemake.output[0], p.sample_rate_hz, p.window_samples, p.overlap_samples)
log.info("FRF: %d frequencies", len(frf))
