from loper_analysis.steps import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.steps import markers

    out = snakemake.output
    markers.markers(
        snakemake.input.c3d,
        out.trc,
        out.gaps,
        snakemake.params.settings,
        summary_out=out.summary,
        lab_angles_out=out.lab_angles,
    )
