from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.impedance import step as impedance

    impedance.subject_fits(snakemake.wildcards.subject, snakemake.params.fits, snakemake.params.settings)
