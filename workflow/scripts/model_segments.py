from _logging import setup

from loper_analysis.processing import model_segments

log = setup(snakemake.log[0])
p = snakemake.params
model_segments(snakemake.input[0], snakemake.output[0], p.side, p.height_m, p.mass_kg, p.user_model)
log.info("segment table of %s", snakemake.input[0])
