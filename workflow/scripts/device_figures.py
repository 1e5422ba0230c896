from _logging import setup

from loper_analysis.device.files import plot_bode, plot_steps

log = setup(snakemake.log[0])
plot_bode(snakemake.input.frf, snakemake.input.summary, snakemake.output.bode)
plot_steps(snakemake.input.average, snakemake.output.steps)
log.info("wrote %s and %s", snakemake.output.bode, snakemake.output.steps)
