from _logging import setup

from loper_analysis.figures import plot_impedance

log = setup(snakemake.log[0])
mean = plot_impedance(snakemake.input[0], snakemake.output[0])
log.info("across-subject mean:\n%s", mean.to_string())
