from _logging import setup

from loper_analysis.dynamics import segment_parameters_from_anthropometry

log = setup(snakemake.log[0])
p = segment_parameters_from_anthropometry(
    snakemake.params.height_m, snakemake.params.mass_kg, snakemake.params.attachment_fraction
)
p.to_tsv(snakemake.output[0])
log.info("representative subject: %s", p)
