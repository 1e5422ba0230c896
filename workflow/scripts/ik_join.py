from _logging import setup

from loper_analysis.processing import ik_join

log = setup(snakemake.log[0])
angles = ik_join(snakemake.input, snakemake.output.mot, snakemake.output.angles, snakemake.params.coordinate_map)
log.info("%d frames, %s", len(angles), list(angles.columns))
