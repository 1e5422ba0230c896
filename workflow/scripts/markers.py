from _logging import setup

from loper_analysis.processing import process_markers

log = setup(snakemake.log[0])
p = snakemake.params
gaps = process_markers(
    snakemake.input[0], snakemake.output.trc, snakemake.output.gaps, p.rotation_deg, p.max_gap_frames,
    p.cutoff_hz, p.order, p.duration_s,
)
log.info("filled gaps:\n%s", gaps.to_string(index=False))
