from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p = snakemake.params
    processing.markers(
        snakemake.input.c3d,
        snakemake.output.trc,
        snakemake.output.gaps,
        p.rotation_deg,
        p.max_gap_frames,
        p.cutoff_hz,
        p.order,
        label_map=p.label_maps or None,
        summary_out=snakemake.output.summary,
        extent_range_m=tuple(p.extent_range_m),
        span_s=p.span_s,
        walking_direction=p.walking_direction,
        min_travel_speed_m_per_s=p.min_travel_speed_m_per_s,
    )
