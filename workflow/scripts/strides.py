from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.strides import step as strides

    inp, out = snakemake.input, snakemake.output
    strides.strides(
        inp.angles, inp.events, out.strides, out.cycles, inp.force or None, snakemake.params.settings, out.dropped
    )
