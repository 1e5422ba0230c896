import pandas as pd
from _logging import setup

from loper_analysis.processing import write_tsv

log = setup(snakemake.log[0])
table = pd.concat([pd.read_csv(f, sep="\t") for f in snakemake.input], ignore_index=True)
write_tsv(table, snakemake.output[0])
log.info("%d rows, status counts:\n%s", len(table), table.status.value_counts().to_string())
