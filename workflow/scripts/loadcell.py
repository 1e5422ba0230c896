from _logging import setup

from loper_analysis.processing import loadcell_forces

log = setup(snakemake.log[0])
p = snakemake.params
forces = loadcell_forces(snakemake.input.c3d, snakemake.input.log, snakemake.output[0], p.sync_channel, p.cutoff_hz, p.order)
log.info("%d frames on the mocap clock", len(forces))
