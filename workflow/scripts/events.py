from loper_analysis.steps import processing, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    processing.events(snakemake.input[0], snakemake.output[0], p.grf_channels, p.threshold_on_n, p.threshold_off_n,
                      p.min_stance_s, p.min_swing_s, p.cutoff_hz, p.order)
