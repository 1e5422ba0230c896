from _logging import setup

from loper_analysis.processing import model_generic

log = setup(snakemake.log[0])
model_generic(snakemake.output[0], snakemake.params.height_m, snakemake.params.mass_kg)
log.info("generic model for %s m, %s kg", snakemake.params.height_m, snakemake.params.mass_kg)
