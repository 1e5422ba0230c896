from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p = snakemake.params
    processing.markers(snakemake.input.c3d, snakemake.output.trc, snakemake.output.gaps, p.rotation_deg,
                       p.max_gap_frames, p.cutoff_hz, p.order, p.duration_s, label_map=p.label_map or None,
                       summary_out=snakemake.output.summary, extent_range_m=tuple(p.extent_range_m))
