from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p, inp, out = snakemake.params, snakemake.input, snakemake.output
    processing.strides(
        inp.angles,
        inp.events,
        out.strides,
        out.cycles,
        inp.force or None,
        p.side,
        p.n_points,
        p.whisker,
        p.max_fraction,
        p.min_valid,
    )
