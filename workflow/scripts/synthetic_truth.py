from _logging import setup

from loper_analysis.synthetic.subjects import true_impedance, write_truth

log = setup(snakemake.log[0])
p = snakemake.params
truth = true_impedance(p.row["subject"], p.seed, p.stiffness, p.damping, p.cv, p.stiffness_bounds, p.damping_bounds)
write_truth(snakemake.output[0], p.row, truth)
log.info("truth of %s: %s", p.row["subject"], truth)
