from loper_analysis.steps import processing, rule_log

p = snakemake.params
with rule_log(snakemake.log[0]):
    processing.markers(snakemake.input[0], snakemake.output.trc, snakemake.output.gaps, p.rotation_deg,
                       p.max_gap_frames, p.cutoff_hz, p.order, p.duration_s)
