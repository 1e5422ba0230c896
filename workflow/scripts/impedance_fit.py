from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    inp, out, p = snakemake.input, snakemake.output, snakemake.params
    impedance.fit(p.trials, inp.angles, inp.strides, inp.force, inp.markers, inp.segments,
                  int(snakemake.wildcards.onset), snakemake.wildcards.subject, out.response, out.counts, out.fit,
                  out.curves, inp.get("truth"), p.null_trials, inp.null_angles, inp.null_strides, p.response,
                  p.identification, force_native=inp.force_native, force_out=out.force)
