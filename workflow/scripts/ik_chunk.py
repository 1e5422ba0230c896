from loper_analysis.steps import ik, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    ik.ik_chunk(snakemake.input.model, snakemake.input.trc, snakemake.output[0], int(snakemake.wildcards.chunk),
                p.n_chunks, **p.settings)
