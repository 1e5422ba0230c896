from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.device import step as device

    inp, out = snakemake.input, snakemake.output
    device.figures(inp.frf, inp.summary, inp.average, out.bode, out.steps)
