from loper_analysis.steps import rule_log, validation

inp, out = snakemake.input, snakemake.output
with rule_log(snakemake.log[0]):
    validation.validation_tables(inp.errors, inp.fits, out.errors, out.fits, out.summary)
