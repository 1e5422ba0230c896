from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.impedance import step as impedance

    impedance.subject_figures(
        snakemake.params.onsets,
        snakemake.input.responses,
        snakemake.input.curves,
        snakemake.wildcards.subject,
        snakemake.output.responses,
        snakemake.output.fit,
    )
