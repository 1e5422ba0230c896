from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import validation

    inp, out = snakemake.input, snakemake.output
    validation.validation_tables(inp.errors, inp.fits, out.errors, out.fits, out.summary)
