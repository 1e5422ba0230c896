from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    impedance.impedance_summary(
        snakemake.input[0],
        snakemake.output.summary,
        snakemake.output.literature,
        tuple(snakemake.params.upper_bounds),
        tuple(snakemake.params.lower_bounds),
    )
