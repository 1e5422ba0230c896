from _logging import setup

from loper_analysis.device.files import write_step_tables

log = setup(snakemake.log[0])
p = snakemake.params
metrics = write_step_tables(
    snakemake.input[0], snakemake.output.metrics, snakemake.output.average, p.sample_rate_hz,
    p.amplitudes_n, p.before_s, p.after_s, p.steady_window_s,
)
log.info("step metrics:\n%s", metrics.to_string())
