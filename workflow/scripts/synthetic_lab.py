from loper_analysis.stages import rule_log

with rule_log(snakemake.log[0]):
    from loper_analysis.stages.synthetic import step as synthetic

    settings, out = snakemake.params.settings, snakemake.output
    files = synthetic.LabSessionFiles.in_design_order(
        settings.design, snakemake.input.truth, out.static, out.c3d, out.logs
    )
    synthetic.lab_session(snakemake.wildcards.subject, snakemake.params.row, files, settings)
