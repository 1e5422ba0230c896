from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.ik import step as ik

    out = snakemake.output
    ik.ik_trial(
        snakemake.input.model,
        snakemake.input.trc,
        out.mot,
        out.angles,
        snakemake.params.settings,
        summary_tsv=out.summary,
        lab_angles=(snakemake.input.lab_angles, out.agreement),
        static_trc=(snakemake.input.static or [None])[0],
    )
