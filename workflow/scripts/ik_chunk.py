from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.ik import step as ik

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
