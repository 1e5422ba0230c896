from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.validation import step as validation

    inp, out = snakemake.input, snakemake.output
    validation.validation_tables(inp.errors, inp.fits, out.errors, out.fits, out.summary)
