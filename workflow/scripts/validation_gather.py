from _logging import setup

from loper_analysis.validation import gather_validation_tables

log = setup(snakemake.log[0])
summary = gather_validation_tables(
    snakemake.input.errors, snakemake.input.fits,
    snakemake.output.errors, snakemake.output.fits, snakemake.output.summary,
)
log.info("summary:\n%s", summary.to_string())
