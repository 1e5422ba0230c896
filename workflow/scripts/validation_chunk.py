from _logging import setup

from loper_analysis.validation import ValidationSettings, validation_chunk_tables

log = setup(snakemake.log[0])
settings = ValidationSettings(**snakemake.params.settings)
chunk = int(snakemake.wildcards.chunk)
log.info("chunk %d of %d with %s", chunk, snakemake.params.n_chunks, settings)
validation_chunk_tables(
    snakemake.input.segments, settings, chunk, snakemake.params.n_chunks,
    snakemake.output.errors, snakemake.output.fits,
)
log.info("done")
