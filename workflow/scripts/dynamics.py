from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.dynamics import step as dynamics
    from loper_analysis.stages.dynamics.files import DynamicsFiles

    i, o = snakemake.input, snakemake.output
    files = DynamicsFiles(i.model_osim, i.ik_mot, i.grf_mot, i.contacts_tsv, i.events_tsv, i.strides_tsv)
    outputs = dynamics.DynamicsOutputs(o.moments, o.cycles, summary=o.summary, figure=o.figure)
    dynamics.inverse_dynamics(files, outputs, snakemake.params.settings)
