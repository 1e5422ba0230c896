from loper_analysis.steps import device, rule_log

inp, out = snakemake.input, snakemake.output
with rule_log(snakemake.log[0]):
    device.figures(inp.frf, inp.summary, inp.average, out.bode, out.steps)
