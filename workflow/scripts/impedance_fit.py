from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import impedance

    impedance.subject_fits(snakemake.wildcards.subject, snakemake.params.fits, snakemake.params.settings)
