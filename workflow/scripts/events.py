from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.events import step as events

    out = snakemake.output
    events.events(snakemake.input.c3d, out.events, snakemake.params.settings, contacts_out=out.contacts)
