from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.transparency import step as transparency

    out = snakemake.output
    transparency.transparency(snakemake.params.files, out.rmsd, out.force, out.figure, snakemake.params.settings)
