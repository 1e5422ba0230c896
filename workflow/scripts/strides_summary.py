from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.strides import step as strides

    p, i = snakemake.params, snakemake.input
    strides.strides_summary(
        p.subject_trial,
        i.strides,
        snakemake.output[0],
        p.min_valid,
        strides.TrialTables(contacts=i.contacts, ik=i.ik, markers=i.markers, agreement=i.agreement, dropped=i.dropped),
    )
