from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    inp, out, p = snakemake.input, snakemake.output, snakemake.params
    impedance.subject_fits(
        p.onsets_ms,
        p.trials,
        p.null_trials,
        dict(zip(p.fit_trials, inp.angles, strict=True)),
        dict(zip(p.fit_trials, inp.strides, strict=True)),
        dict(zip(p.own_trials, inp.force, strict=True)),
        dict(zip(p.own_trials, inp.force_native, strict=True)),
        dict(zip(p.own_trials, inp.markers, strict=True)),
        inp.segments,
        snakemake.wildcards.subject,
        out.response,
        out.counts,
        out.fit,
        out.curves,
        out.force,
        inp.get("truth"),
        p.response,
        p.identification,
    )
