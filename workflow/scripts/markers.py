from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.markers import step as markers

    out = snakemake.output
    markers.markers(
        snakemake.input.c3d,
        out.trc,
        out.gaps,
        snakemake.params.settings,
        summary_out=out.summary,
        lab_angles_out=out.lab_angles,
    )
