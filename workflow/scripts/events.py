from _logging import setup

from loper_analysis.processing import detect_events

log = setup(snakemake.log[0])
p = snakemake.params
events = detect_events(
    snakemake.input[0], snakemake.output[0], p.grf_channels, p.threshold_on_n, p.threshold_off_n,
    p.min_stance_s, p.min_swing_s, p.cutoff_hz, p.order,
)
log.info("events per side and kind:\n%s", events.groupby(["side", "event"]).size().to_string())
