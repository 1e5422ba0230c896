from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import ik

    p = snakemake.params
    ik.ik_chunk(
        snakemake.input.model,
        snakemake.input.trc,
        snakemake.output[0],
        int(snakemake.wildcards.chunk),
        p.n_chunks,
        p.settings,
        (snakemake.input.static or [None])[0],
    )
