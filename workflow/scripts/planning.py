from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.planning import step as planning

    p, out = snakemake.params, snakemake.output
    planning.plan(p.files, p.subject, p.settings, out.table, out.answers, unplannable="note")
