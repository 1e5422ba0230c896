from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.impedance import step as impedance

    impedance.impedance_summary(
        snakemake.input[0],
        snakemake.output.summary,
        snakemake.output.literature,
        tuple(snakemake.params.upper_bounds),
        tuple(snakemake.params.lower_bounds),
    )
