from loper_analysis.steps import impedance, rule_log

with rule_log(snakemake.log[0]):
    impedance.subject_figures(snakemake.params.onsets, snakemake.input.responses, snakemake.input.curves,
                              snakemake.wildcards.subject, snakemake.output.responses, snakemake.output.fit)
