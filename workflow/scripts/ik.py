from _logging import setup

from loper_analysis.processing import ik_trial

log = setup(snakemake.log[0])
p, out = snakemake.params, snakemake.output
angles = ik_trial(snakemake.input.model, snakemake.input.trc, out.mot, out.angles, p.coordinate_map, **p.settings)
log.info("%d frames, %s", len(angles), list(angles.columns))
