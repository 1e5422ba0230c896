from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import ik

    out = snakemake.output
    ik.ik_join(snakemake.input, out.mot, out.angles, snakemake.params.settings, summary_tsv=out.summary)
