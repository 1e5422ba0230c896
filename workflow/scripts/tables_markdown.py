from _logging import setup

from loper_analysis.tables import write_markdown

log = setup(snakemake.log[0])
write_markdown(dict(zip(snakemake.params.headings, snakemake.input)), snakemake.output[0])
log.info("rendered %d tables", len(snakemake.input))
