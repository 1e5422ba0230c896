import pandas as pd
from _logging import setup

from loper_analysis.impedance import impedance_summary, literature_table
from loper_analysis.processing import write_tsv

log = setup(snakemake.log[0])
summary = impedance_summary(pd.read_csv(snakemake.input[0], sep="\t"))
write_tsv(summary, snakemake.output.summary)
write_tsv(literature_table(summary), snakemake.output.literature)
log.info("summary:\n%s", summary.to_string(index=False))
