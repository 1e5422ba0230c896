from _logging import setup

from loper_analysis.processing import ik_chunk

log = setup(snakemake.log[0])
p = snakemake.params
ik_chunk(snakemake.input.model, snakemake.input.trc, snakemake.output[0], int(snakemake.wildcards.chunk), p.n_chunks,
         **p.settings)
