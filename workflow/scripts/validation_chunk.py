from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.validation import step as validation

    out = snakemake.output
    validation.validation_chunk(
        snakemake.input.segments,
        snakemake.params.settings,
        int(snakemake.wildcards.chunk),
        snakemake.params.n_chunks,
        out.errors,
        out.fits,
    )
