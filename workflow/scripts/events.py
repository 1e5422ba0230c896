from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import processing

    p = snakemake.params
    processing.events(snakemake.input.c3d, snakemake.output.events, p.grf_channels, p.threshold_on_n,
                      p.threshold_off_n, p.min_stance_s, p.min_swing_s, p.cutoff_hz, p.order, p.foot_markers,
                      p.plate_sides, p.label_map, p.rotation_deg, p.band_n, p.max_rest_n, snakemake.output.contacts)
