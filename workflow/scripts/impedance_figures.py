from _logging import setup

from loper_analysis.figures import plot_fit, plot_responses

log = setup(snakemake.log[0])
onsets = snakemake.params.onsets
subject = snakemake.wildcards.subject
peaks = plot_responses(dict(zip(onsets, snakemake.input.responses)), snakemake.output.responses,
                       title=f"{subject}: perturbed vs unperturbed")
plot_fit(dict(zip(onsets, snakemake.input.curves)), snakemake.output.fit, title=f"{subject}: model fit vs data")
log.info("peak |response| (rad):\n%s", peaks.to_string())
