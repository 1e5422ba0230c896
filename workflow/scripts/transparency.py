from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import transparency

    inp, out = snakemake.input, snakemake.output
    transparency.transparency(
        snakemake.params.subjects,
        inp.no_device_strides,
        inp.no_device_cycles,
        inp.device_strides,
        inp.device_cycles,
        out.rmsd,
        out.force,
        out.figure,
        snakemake.params.side,
        snakemake.params.min_strides,
    )
