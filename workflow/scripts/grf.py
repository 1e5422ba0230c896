from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import grf

    p = snakemake.params
    grf.grf(snakemake.input[0], snakemake.output[0], p.rotation_deg, p.threshold_n, p.band_n, p.max_rest_n)
