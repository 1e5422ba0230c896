from _logging import setup

from loper_analysis.validation import plot_validation_errors

log = setup(snakemake.log[0])
plot_validation_errors(snakemake.input.errors, snakemake.output[0])
log.info("wrote %s", snakemake.output[0])
