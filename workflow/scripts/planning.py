from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import planning

    p, out = snakemake.params, snakemake.output
    planning.plan(p.files, p.subject, p.settings, out.table, out.answers, unplannable="note")
