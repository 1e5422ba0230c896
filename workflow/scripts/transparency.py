from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import transparency

    out = snakemake.output
    transparency.transparency(snakemake.params.files, out.rmsd, out.force, out.figure, snakemake.params.settings)
