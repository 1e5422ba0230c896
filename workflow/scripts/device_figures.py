from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import device

    inp, out = snakemake.input, snakemake.output
    device.figures(inp.frf, inp.summary, inp.average, out.bode, out.steps)
