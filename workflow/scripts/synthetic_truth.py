from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.synthetic import step as synthetic

    p = snakemake.params
    synthetic.truth(snakemake.output[0], p.row, p.truth, p.seed)
