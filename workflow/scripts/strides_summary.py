from _logging import setup

from loper_analysis.processing import stride_summary

log = setup(snakemake.log[0])
p = snakemake.params
table = stride_summary(dict(zip(map(tuple, p.subject_trial), snakemake.input)), snakemake.output[0], p.min_valid)
for row in table[table.status != "ok"].itertuples():
    log.warning("%s %s: only %d valid strides (minimum %d)", row.subject, row.trial, row.n_kept, p.min_valid)
log.info("strides:\n%s", table.to_string(index=False))
