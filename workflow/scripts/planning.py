from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import planning

    inp, out, p = snakemake.input, snakemake.output, snakemake.params
    planning.plan(
        p.trials,
        inp.angles,
        inp.strides,
        inp.segments,
        p.subject,
        p.onsets,
        p.strides,
        out.table,
        out.answers,
        impedance_tsvs=inp.impedance,
        targets=p.targets,
        pulse_force_n=p.pulse_force_n,
        pulse_duration_s=p.pulse_duration_s,
        response=p.response,
        identification=dict(p.identification),
        device=dict(p.device),
        unplannable="note",
    )
