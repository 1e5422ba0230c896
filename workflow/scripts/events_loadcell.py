from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.events import step as events

    inp, out, p = snakemake.input, snakemake.output, snakemake.params
    events.events_loadcell(inp.c3d, inp.log, out.events, out.contacts, out.force, out.native, p.events, p.loadcell)
