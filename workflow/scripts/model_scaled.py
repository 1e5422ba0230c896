from _logging import setup

from loper_analysis.processing import model_scaled

log = setup(snakemake.log[0])
model_scaled(snakemake.input.generic, snakemake.input.static, snakemake.output[0], snakemake.params.mass_kg)
log.info("scaled %s to %s", snakemake.input.generic, snakemake.input.static)
