from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.ik import step as ik

    out = snakemake.output
    ik.ik_join(
        snakemake.input.chunks,
        out.mot,
        out.angles,
        snakemake.params.settings,
        summary_tsv=out.summary,
        lab_angles=(snakemake.input.lab_angles, out.agreement),
    )
