from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    impedance.subject_figures(
        snakemake.params.onsets,
        snakemake.input.responses,
        snakemake.input.curves,
        snakemake.wildcards.subject,
        snakemake.output.responses,
        snakemake.output.fit,
    )
