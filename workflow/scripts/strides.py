import warnings

from _logging import setup

from loper_analysis.processing import cut_strides

log = setup(snakemake.log[0])
p = snakemake.params
force = snakemake.input.force or None
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    table = cut_strides(
        snakemake.input.angles, snakemake.input.events, snakemake.output.strides, snakemake.output.cycles,
        force, p.side, p.n_points, p.whisker, p.max_fraction, p.min_valid,
    )
for w in caught:
    log.warning("%s", w.message)
log.info("%d strides, %d kept", len(table), int((~table["removed"]).sum()))
